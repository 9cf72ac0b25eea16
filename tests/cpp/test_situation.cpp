// Sight models (Huerta eqs. 9-18, Grisales eq. 16), quality likelihoods, the forward filter (eqs. 35-38)
// against a hand calculation, and the IUKF (Table VI) reducing to the UKF when the probabilities are certain.
#include <catch2/catch.hpp>
#include <cmath>

#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/situation/forward.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

using namespace nlosloc;
using namespace nlosloc::situation;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
namespace nn = nlosloc::noise;

template class nlosloc::Iukf<ConstantVelocity2>;
template class nlosloc::Iukf<ConstantVelocityClock2>;

TEST_CASE("transversal speed eq. 10", "[situation]") {
  const Eigen::Vector2d q(0, 0), p(100, 0);
  CHECK_THAT(transversal_speed(p, Eigen::Vector2d(3, 4), q), WithinAbs(4.0, 1e-12));
  CHECK_THAT(transversal_speed(p, Eigen::Vector2d(5, 0), q), WithinAbs(0.0, 1e-12));  // radial: no change
  CHECK_THAT(transversal_speed(q, Eigen::Vector2d(3, 4), q), WithinAbs(5.0, 1e-12));
  // a position that is not finite is not "on the anchor": NaN, not ||v||
  CHECK(std::isnan(transversal_speed(Eigen::Vector2d(std::nan(""), 0), Eigen::Vector2d(3, 4), q)));
}

TEST_CASE("speed-dependent transitions: hand values of eqs. 15, 17, 18", "[situation]") {
  // w = 10 m/s, dt = 0.01 s -> a = 0.1 m; E{L_LOS} = 30 m, E{L_NLOS} = 5 m (scenario H1).
  const Mat<2, 2> T15 = speed_transition_single(10.0, 0.01, 30.0, 5.0);
  CHECK_THAT(T15(0, 0), WithinRel(30.0 / 30.1, 1e-14));
  CHECK_THAT(T15(0, 1), WithinRel(0.1 / 30.1, 1e-14));
  CHECK_THAT(T15(1, 0), WithinRel(0.1 / 5.1, 1e-14));
  CHECK_THAT(T15(1, 1), WithinRel(5.0 / 5.1, 1e-14));
  const double rho = 1.0 / (1.0 - (0.1 / 30.1) * (0.1 / 5.1));
  const Mat<2, 2> T17 = speed_transition_multiple(10.0, 0.01, 30.0, 5.0);
  CHECK_THAT(T17(0, 0), WithinRel(30.0 / 30.1 * rho, 1e-14));
  CHECK_THAT(T17(0, 1), WithinRel(0.1 / 30.1 * 5.0 / 5.1 * rho, 1e-14));
  CHECK_THAT(T17(1, 0), WithinRel(0.1 / 5.1 * 30.0 / 30.1 * rho, 1e-14));
  CHECK_THAT(T17(1, 1), WithinRel(5.0 / 5.1 * rho, 1e-14));
  CHECK_THAT(T17.row(0).sum(), WithinAbs(1.0, 1e-15));
  CHECK_THAT(T17.row(1).sum(), WithinAbs(1.0, 1e-15));
  const Mat<2, 2> T18 = speed_transition_memoryless(30.0, 5.0);
  CHECK_THAT(T18(0, 1), WithinRel(5.0 / 35.0, 1e-15));  // p_N = 0.143 (paper: 0.14)
  CHECK_THAT(T18(1, 0), WithinRel(30.0 / 35.0, 1e-15));
  // eq. (17) tends to eq. (18) for w dt >> E{L} and to eq. (15) for w dt << E{L}
  CHECK_THAT(speed_transition_multiple(1e9, 1.0, 30, 5)(0, 1), WithinAbs(5.0 / 35.0, 1e-6));
  CHECK_THAT(speed_transition_multiple(1e-3, 0.01, 30, 5)(0, 1),
             WithinRel(speed_transition_single(1e-3, 0.01, 30, 5)(0, 1), 1e-5));
  // zero speed: the situation cannot change
  CHECK(speed_transition_multiple(0.0, 0.01, 30, 5).isIdentity(0.0));
  CHECK_THROWS_AS(speed_transition_single(-1.0, 0.01, 30, 5), std::invalid_argument);
}

TEST_CASE("fixed chain with K_sight schedule (Grisales eq. 16)", "[situation]") {
  MatX Q(3, 3);
  Q << 0.970, 0.010, 0.020, 0.010, 0.970, 0.020, 0.025, 0.025, 0.950;  // Grisales eq. (38)
  const SightModel m = SightModel::fixed(Q, 150);
  CHECK(m.num_conditions() == 3);
  CHECK(m.transition(149).isIdentity(0.0));
  CHECK(m.transition(300).isApprox(Q));
  CHECK_THAT(m.initial().sum(), WithinAbs(1.0, 1e-12));
  CHECK((m.initial().transpose() * Q).isApprox(m.initial().transpose(), 1e-12));  // stationary prior
  Rng rng(3);
  int s = 1;
  for (long k = 1; k < 150; ++k) s = m.sample_next(s, k, 0.0, rng);
  CHECK(s == 1);  // no change before K_sight
  MatX bad = Q;
  bad(0, 0) = 0.5;
  CHECK_THROWS_AS(SightModel::fixed(bad), std::invalid_argument);
  CHECK_THROWS_AS(SightModel::fixed(Q, 0), std::invalid_argument);
}

TEST_CASE("sampled chain visits NLOS with the eq. 18 frequency", "[situation]") {
  const SightModel m = SightModel::speed_dependent(30.0, 5.0, 0.01);
  CHECK_THAT(m.initial()(1), WithinRel(5.0 / 35.0, 1e-12));
  Rng rng(11);
  int s = m.sample_initial(rng);
  long nlos = 0;
  const long n = 400000;
  for (long k = 1; k <= n; ++k) {
    s = m.sample_next(s, k, 10.0, rng);
    nlos += s;
  }
  CHECK_THAT(static_cast<double>(nlos) / n, WithinAbs(5.0 / 35.0, 0.03));
  const SightProcess proc(m, 3);
  const VecXi s0 = proc.sample_initial(rng);
  const VecXi s1 = proc.sample_next(s0, 1, VecX::Constant(3, 10.0), rng);
  CHECK(s1.size() == 3);
  CHECK_THROWS_AS(proc.sample_next(s0, 1, VecX(), rng), std::invalid_argument);
}

TEST_CASE("quality likelihoods from any distribution, empirical included", "[situation]") {
  const QualityModel q({nn::Beta(4, 1.5), nn::Beta(1.5, 4)});
  CHECK_THAT(q.log_likelihood(0.8, 0), WithinAbs(nn::Beta(4, 1.5).log_pdf(0.8), 1e-14));
  CHECK(q.log_likelihood(std::nan(""), 1) == 0.0);
  Rng rng(5);
  VecX samples(500);
  for (int i = 0; i < 500; ++i) samples(i) = nn::Beta(4, 1.5).sample(rng);
  const QualityModel qe({nn::Empirical(samples), nn::Beta(1.5, 4)});
  CHECK(qe.log_likelihood(0.8, 0) > qe.log_likelihood(0.8, 1));
  CHECK_THROWS_AS(QualityModel({}), std::invalid_argument);
}

TEST_CASE("forward filter against a hand calculation (eqs. 36-38)", "[situation]") {
  MatX T(2, 2);
  T << 0.9, 0.1, 0.2, 0.8;
  VecX pi0(2);
  pi0 << 0.5, 0.5;
  const SightProcess proc(SightModel::fixed(T, 1, pi0), 1);
  const QualityModel q({nn::Normal(1.0, 0.5), nn::Normal(0.0, 0.5)});
  ForwardFilter f(proc, q);
  VecX o(1);
  o << 0.8;
  f.step(o);
  // by hand: predicted = [0.55, 0.45]; likelihoods N(0.8; 1, .5), N(0.8; 0, .5)
  const double l0 = std::exp(-0.5 * 0.04 / 0.25), l1 = std::exp(-0.5 * 0.64 / 0.25);
  const double g0 = 0.55 * l0 / (0.55 * l0 + 0.45 * l1);
  CHECK_THAT(f.predicted()(0, 0), WithinAbs(0.55, 1e-14));
  CHECK_THAT(f.probabilities()(0, 0), WithinAbs(g0, 1e-14));
  CHECK_THAT(f.probabilities().row(0).sum(), WithinAbs(1.0, 1e-14));  // eq. (38)
  o << std::nan("");
  f.step(o);  // missing statistic: prediction only
  CHECK_THAT(f.probabilities()(0, 0), WithinAbs(g0 * 0.9 + (1 - g0) * 0.2, 1e-14));
  CHECK(f.argmax()(0) == 0);
  CHECK_THROWS_AS(f.update(VecX::Zero(2)), std::invalid_argument);
}

TEST_CASE("forward filter: a statistic far out under the only predicted condition is possible",
          "[situation]") {
  // The normalisation of eqs. (37)-(38) took the largest log p(o | k) alone: when the only predicted
  // condition's density lay over ~745 nats below another's, the sum underflowed to 0 and update()
  // refused the statistic as impossible.
  const QualityModel q({nn::Normal(0.0, 1.0), nn::Normal(50.0, 1.0)});
  VecX pi(2);
  pi << 1.0, 0.0;
  ForwardFilter f(SightProcess(SightModel::fixed(MatX::Identity(2, 2), 1, pi), 1), q);
  VecX o(1);
  o << 40.0;
  CHECK_THAT(f.step(o), WithinRel(-800.0 - 0.91893853320467274, 1e-14));  // log N(40; 0, 1)
  CHECK(f.probabilities()(0, 0) == 1.0);
  CHECK(f.probabilities()(0, 1) == 0.0);
  // Reached from a regular chain: K_sight = 10 keeps T = I between its change epochs.
  MatX T(2, 2);
  T << 0.9, 0.1, 0.1, 0.9;
  ForwardFilter g(SightProcess(SightModel::fixed(T, 10), 1), q);
  o << 50.0;
  g.step(o);  // LOS's density e^-1250 of NLOS's: P(NLOS) = 1
  CHECK(g.probabilities()(0, 1) == 1.0);
  o << 5.0;
  CHECK_THAT(g.step(o), WithinRel(-1012.5 - 0.91893853320467274, 1e-14));  // log N(5; 50, 1)
  CHECK(g.probabilities()(0, 1) == 1.0);
}

namespace {
/// Two speed-dependent anchors with Beta quality statistics, after one step.
struct TwoAnchors {
  SightProcess proc{SightModel::speed_dependent(30, 5, 0.1), 2};
  ForwardFilter f{proc, QualityModel({nn::Beta(4, 1.5), nn::Beta(1.5, 4)})};
  VecX o = (VecX(2) << 0.9, 0.2).finished(), w = (VecX(2) << 3.0, 1.0).finished();
  TwoAnchors() { f.step(o, w); }
};
}  // namespace

TEST_CASE("forward filter: a rejected call changes nothing, and set_probabilities is the next prior",
          "[situation]") {
  TwoAnchors t;
  ForwardFilter& f = t.f;
  const VecX o = t.o, w = t.w;
  const MatX g0 = f.probabilities(), p0 = f.predicted();
  const long k0 = f.step_index();
  const double e0 = f.last_log_evidence();
  auto unchanged = [&] {
    CHECK(f.probabilities() == g0);
    CHECK(f.predicted() == p0);
    CHECK(f.step_index() == k0);
    CHECK(f.last_log_evidence() == e0);
  };
  CHECK_THROWS_WITH(f.step(VecX::Zero(1), w), "o: expected shape (2, 1), got (1, 1)");
  unchanged();
  VecX wb = w;
  wb(1) = -1.0;
  CHECK_THROWS_WITH(f.predict(wb), Catch::Matchers::StartsWith("speeds: expected finite values >= 0"));
  unchanged();
  wb(1) = std::nan("");
  CHECK_THROWS_WITH(f.step(o, wb), Catch::Matchers::StartsWith("speeds: expected finite values >= 0"));
  unchanged();
  VecX ob = o;
  ob(1) = 7.0;  // outside [0, 1]: zero density under both Beta pdfs, found after the prediction
  CHECK_THROWS_WITH(f.step(ob, w), "o: statistic of anchor 1 has zero density under every condition");
  unchanged();
  ob << 0.1, 7.0;  // anchor 0 is fine: it must not be updated either
  CHECK_THROWS_WITH(f.update(ob), "o: statistic of anchor 1 has zero density under every condition");
  unchanged();
  ob << 0.1, std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(f.update(ob),
                    "o: expected finite statistics, or NaN for a missing one; got inf at anchor 1");
  unchanged();
  // set_probabilities replaces the prior of the next update: certain NLOS stays NLOS
  MatX certain(2, 2);
  certain << 0, 1, 0, 1;
  f.set_probabilities(certain);
  f.update(o);
  CHECK(f.probabilities() == certain);
  CHECK_THROWS_WITH(f.set_probabilities(MatX::Constant(2, 2, 0.3)),
                    "gamma: every row must hold probabilities (>= 0) summing to 1; row 0 does not");
}

TEST_CASE("forward filter restore and the speed chain refuse what they used to store silently",
          "[situation]") {
  TwoAnchors t;
  const SightProcess& proc = t.proc;
  ForwardFilter& f = t.f;
  const VecX o = t.o, w = t.w;
  ForwardFilter::Snapshot good;
  f.save(good);
  const auto refused = [&](ForwardFilter::Snapshot s) {
    try {
      f.restore(s);
    } catch (const std::invalid_argument& e) {
      CHECK(f.probabilities() == good.gamma);  // unchanged
      CHECK(f.step_index() == good.k);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  ForwardFilter::Snapshot s = good;
  s.gamma.setConstant(std::nan(""));
  CHECK(refused(s) == "snapshot.gamma: expected finite values (no NaN or inf)");
  s = good;
  s.pred.setConstant(7.0);
  CHECK(refused(s) == "snapshot.pred: every row must hold probabilities (>= 0) summing to 1; row 0 does not");
  s = good;
  s.k = -5;
  CHECK(refused(s) == "snapshot.k: expected a step index >= 0, got -5");
  s = good;
  s.log_evidence = std::nan("");
  CHECK(refused(s) == "snapshot.log_evidence: expected a finite value, got nan");
  s.log_evidence = std::numeric_limits<double>::infinity();  // update() never gives one (was accepted)
  CHECK(refused(s) == "snapshot.log_evidence: expected a finite value, got inf");
  s.log_evidence = -std::numeric_limits<double>::infinity();
  CHECK(refused(s) == "snapshot.log_evidence: expected a finite value, got -inf");
  CHECK(refused(good) == "accepted");

  // Eq. (17) at speeds where 1 - p_LN p_NL rounds to 0: finite rows summing to 1 (inf entries before), and
  // the forward filter stays a probability
  const Mat<2, 2> T = speed_transition_multiple(1e17, 1.0, 1.0, 1.0);
  CHECK(T.allFinite());
  CHECK_THAT(T.row(0).sum(), WithinAbs(1.0, 1e-15));
  CHECK_THAT(T(0, 1), WithinRel(0.5, 1e-12));  // a L_N / (a (L_L + L_N) + L_L L_N) -> 1/2
  const Mat<2, 2> T8 = speed_transition_multiple(1e8, 1.0, 1.0, 1.0);  // rows drifted by 3e-9 here
  CHECK_THAT(T8.row(1).sum(), WithinAbs(1.0, 1e-15));
  CHECK_THROWS_WITH(speed_transition_single(1e200, 1e200, 1, 1),
                    Catch::Matchers::StartsWith("w, dt: the transversal distance w * dt overflows"));
  VecX fast(2);
  fast << 1e17, 1.0;
  f.step(o, fast);
  CHECK(f.probabilities().allFinite());
  CHECK_THAT(f.probabilities().row(0).sum(), WithinAbs(1.0, 1e-12));
  // the process names its own arguments
  CHECK_THROWS_WITH(proc.model(7), "b: expected an anchor index in [0, 2), got 7");
  Rng rng(1);
  VecXi cur = VecXi::Zero(2);
  VecX bad(2);
  bad << 1.0, std::nan("");
  CHECK_THROWS_WITH(proc.sample_next(cur, 1, bad, rng),
                    "speeds: expected finite transversal speeds >= 0, got nan at anchor 1");
  CHECK_THROWS_WITH(proc.log_transition(cur, cur, 1, bad),
                    "speeds: expected finite transversal speeds >= 0, got nan at anchor 1");
  // speeds a fixed chain does not read may be left out, but are checked when given (they were ignored)
  const SightProcess fixed_proc(SightModel::fixed((MatX(2, 2) << 0.9, 0.1, 0.2, 0.8).finished()), 2);
  CHECK_NOTHROW(fixed_proc.sample_next(cur, 1, VecX(), rng));
  CHECK_NOTHROW(fixed_proc.log_transition(cur, cur, 1, VecX()));
  CHECK_THROWS_WITH(fixed_proc.sample_next(cur, 1, bad, rng),
                    "speeds: expected finite transversal speeds >= 0, got nan at anchor 1");
  CHECK_THROWS_WITH(fixed_proc.log_transition(cur, cur, 1, VecX::Ones(3)),
                    "speeds: expected shape (2, 1), got (3, 1)");
  ForwardFilter ff(fixed_proc, QualityModel({nn::Beta(4, 1.5), nn::Beta(1.5, 4)}));
  const MatX ff0 = ff.probabilities();
  CHECK_THROWS_WITH(ff.step(o, bad), "speeds: expected finite values >= 0, got nan at anchor 1");
  CHECK_THROWS_WITH(ff.predict(VecX::Ones(1)), "speeds: expected shape (2, 1), got (1, 1)");
  CHECK(ff.probabilities() == ff0);
  CHECK(ff.step_index() == 0);
  ff.step(o);
  CHECK(ff.step_index() == 1);
  // eq. (18) does not read w, but w is checked as for eqs. (15) and (17) (it was not)
  const SightModel memoryless = SightModel::speed_dependent(30, 5, 0.1, SpeedModel::kMemoryless);
  for (const double wb : {-5.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    CHECK_THROWS_WITH(memoryless.transition(1, wb),
                      Catch::Matchers::StartsWith("w: expected a finite value >= 0"));
    CHECK_THROWS_WITH(memoryless.sample_next(0, 1, wb, rng),
                      Catch::Matchers::StartsWith("w: expected a finite value >= 0"));
  }
  CHECK(memoryless.transition(1, 3.0) == memoryless.base_matrix());
  // the vector forms of the quality model name their argument s and the anchor, not the inner z
  const QualityModel qm({nn::Beta(4, 1.5), nn::Beta(1.5, 4)});
  CHECK_THROWS_WITH(qm.log_likelihood(o, (VecXi(2) << 0, 2).finished()),
                    "s: expected conditions in [0, N_z = 2), got 2 at anchor 1");
  CHECK_THROWS_WITH(qm.sample((VecXi(2) << -1, 0).finished(), rng),
                    "s: expected conditions in [0, N_z = 2), got -1 at anchor 0");
  // a statistic where a density is infinite (Beta(0.5, 4) at 0) is named as such, not as "impossible"
  ForwardFilter g(SightProcess(SightModel::speed_dependent(30, 5, 0.1), 1),
                  QualityModel({nn::Beta(4, 1.5), nn::Beta(0.5, 4)}));
  const MatX g0 = g.probabilities();
  CHECK_THROWS_WITH(g.step(VecX::Zero(1), VecX::Ones(1)),
                    Catch::Matchers::StartsWith("o: statistic of anchor 0 has an infinite density"));
  CHECK(g.probabilities() == g0);
}

TEST_CASE("a reducible chain starts from the uniform prior", "[situation]") {
  // T = I has every distribution stationary: no unique answer, so the documented uniform fallback
  CHECK(SightModel::fixed(MatX::Identity(2, 2)).initial().isApprox(VecX::Constant(2, 0.5)));
  CHECK(SightModel::fixed(MatX::Identity(3, 3)).initial().isApprox(VecX::Constant(3, 1.0 / 3.0)));
  // an absorbing LOS state is reducible but has a unique stationary vector: (1, 0)
  MatX T(2, 2);
  T << 1.0, 0.0, 0.5, 0.5;
  const VecX pi = SightModel::fixed(T).initial();
  CHECK_THAT(pi(0), WithinAbs(1.0, 1e-12));
  CHECK_THAT(pi(1), WithinAbs(0.0, 1e-12));
  CHECK_THROWS_WITH(SightProcess(SightModel::fixed(T), 0), "num_anchors: expected an integer >= 1, got 0");
}

namespace {
MeasurementStack iukf_stack() {
  MatX anchors(3, 2);
  anchors << 0, 0, 1000, 0, 0, 1000;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 2);
  for (int b = 0; b < 3; ++b) st.add_toa(b, {nn::Normal(0, 3), nn::Rayleigh::from_variance(2000)});
  st.add_aoa(0, {nn::Normal(0, 0.01), nn::Normal(0, 0.05)});
  return st;
}
}  // namespace

TEST_CASE("IUKF reduces to the UKF when the forward filter is certain", "[situation][iukf]") {
  const ConstantVelocity2 motion(0.1, 1.0);
  const MeasurementStack st = iukf_stack();
  Gaussian<4> g;
  g.mean << 300, 400, 1, 2;
  g.cov = Vec<4>(100, 100, 4, 4).asDiagonal();
  const SightProcess proc(SightModel::speed_dependent(30, 5, 0.1), 3);
  const QualityModel q({nn::Beta(4, 1.5), nn::Beta(1.5, 4)});
  Iukf<ConstantVelocity2> iukf(motion, st, g, ForwardFilter(proc, q));
  Ukf<ConstantVelocity2> ukf(motion, st, g);
  VecXi s(3);
  s << 0, 1, 0;
  MatX gamma = MatX::Zero(3, 2);
  for (int b = 0; b < 3; ++b) gamma(b, s(b)) = 1.0;
  VecX y(4);
  y << 500, 850, 640, 0.9;
  iukf.predict();
  const StepResult ri = iukf.update_with_probabilities(y, gamma);
  const StepResult ru = ukf.step(y, s);
  CHECK((iukf.mean() - ukf.mean()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((iukf.cov() - ukf.cov()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK_THAT(ri.log_likelihood, WithinAbs(ru.log_likelihood, 1e-9));
  // uncertain probabilities inflate the innovation covariance: a smaller gain than under LOS
  Iukf<ConstantVelocity2> mixed(motion, st, g, ForwardFilter(proc, q));
  Ukf<ConstantVelocity2> los(motion, st, g);
  mixed.predict();
  mixed.update_with_probabilities(y, MatX::Constant(3, 2, 0.5));
  los.step(y, VecXi::Zero(3));
  CHECK(mixed.cov().trace() > los.cov().trace());
  // ... and equals a UKF whose row noise has the mixture's moments, computed here by hand (Huerta Table
  // VI.2 / eq. 40, N_z = 2, gamma = 0.5): TOA rows N(0, 3^2) / Rayleigh of variance 2000, AOA row
  // N(0, 0.01^2) / N(0, 0.05^2)
  const double sr = std::sqrt(2.0 * 2000.0 / (4.0 - kPi));  // Rayleigh scale
  const double mr = sr * std::sqrt(kPi / 2.0);              // and mean
  const double toa_mean = 0.5 * mr;
  const double toa_var = 0.5 * 9.0 + 0.5 * (2000.0 + mr * mr) - toa_mean * toa_mean;
  const double aoa_var = 0.5 * 1e-4 + 0.5 * 25e-4;
  MatX anchors(3, 2);
  anchors << 0, 0, 1000, 0, 0, 1000;
  MeasurementStack mst(ConstantVelocity2::layout(), anchors, 2);
  for (int b = 0; b < 3; ++b)
    mst.add_toa(b, {nn::Normal(toa_mean, std::sqrt(toa_var)), nn::Normal(toa_mean, std::sqrt(toa_var))});
  mst.add_aoa(0, {nn::Normal(0, std::sqrt(aoa_var)), nn::Normal(0, std::sqrt(aoa_var))});
  Ukf<ConstantVelocity2> moments(motion, mst, g);
  Iukf<ConstantVelocity2> half(motion, st, g, ForwardFilter(proc, q));
  half.predict();
  const StepResult rh = half.update_with_probabilities(y, MatX::Constant(3, 2, 0.5));
  const StepResult rm = moments.step(y, VecXi::Zero(3));
  CHECK((half.mean() - moments.mean()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((half.cov() - moments.cov()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK_THAT(rh.log_likelihood, WithinAbs(rm.log_likelihood, 1e-9));
  // gamma must hold probabilities; a rejected update changes nothing
  const Vec<4> hm = half.mean();
  CHECK_THROWS_WITH(half.update_with_probabilities(y, MatX::Constant(3, 2, 0.3)),
                    "gamma: every row must hold probabilities (>= 0) summing to 1; row 0 does not");
  MatX neg(3, 2);
  neg << 2, -1, 0.5, 0.5, 0.5, 0.5;
  CHECK_THROWS_WITH(half.update_with_probabilities(y, neg),
                    "gamma: every row must hold probabilities (>= 0) summing to 1; row 0 does not");
  CHECK(half.mean() == hm);
  // full step with quality statistics
  Iukf<ConstantVelocity2> f(motion, st, g, ForwardFilter(proc, q));
  VecX o(3);
  o << 0.9, 0.1, 0.9;
  const StepResult r = f.step_quality(y, o);
  CHECK(std::isfinite(r.log_likelihood));
  CHECK(f.sight_estimate()(1) == 1);
  CHECK_THROWS_AS(f.step_quality(y, VecX::Zero(2)), std::invalid_argument);
  // A statistic impossible under every condition throws after the prediction: the filter and its
  // forward filter are restored (the snapshot path of step_quality).
  const Vec<4> m0 = f.mean();
  const Mat<4, 4> P0 = f.cov();
  const MatX p0 = f.forward().probabilities();
  const long k0 = f.forward().step_index();
  const double t0 = f.time();
  VecX bad = o;
  bad(2) = 7.0;  // outside the support of both quality pdfs
  CHECK_THROWS_WITH(f.step_quality(y, bad), Catch::Matchers::Contains("o: statistic of anchor 2"));
  CHECK(f.mean() == m0);
  CHECK(f.cov() == P0);
  CHECK(f.forward().probabilities() == p0);
  CHECK(f.forward().step_index() == k0);
  CHECK(f.time() == t0);
}

TEST_CASE("closed-form switch probability equals eqs. 15, 17, 18", "[situation]") {
  for (auto form : {SpeedModel::kSingle, SpeedModel::kMultiple, SpeedModel::kMemoryless}) {
    const SightModel m = SightModel::speed_dependent(30.0, 5.0, 0.01, form);
    for (double w : {0.0, 3.0, 10.0, 1e4}) {
      const MatX T = m.transition(1, w);
      CHECK_THAT(speed_switch_probability(m, 0, w), WithinAbs(T(0, 1), 1e-14));
      CHECK_THAT(speed_switch_probability(m, 1, w), WithinAbs(T(1, 0), 1e-14));
    }
  }
}
