// Snapshot baselines (snapshot/*): the Gauss-Newton LOS fix and its closed-form start on exact data, MLE-LOS
// on a range + bearing pair, and CHEN / CONG / URR on hand-built geometries with known NLOS anchors.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "nlosloc/snapshot/snapshot.hpp"

using namespace nlosloc;
using namespace nlosloc::snapshot;
using Catch::Matchers::WithinAbs;

template class nlosloc::sim::SnapshotEstimator<MleLos>;
template class nlosloc::sim::SnapshotEstimator<Chen>;
template class nlosloc::sim::SnapshotEstimator<Cong>;
template class nlosloc::sim::SnapshotEstimator<Urruela>;

namespace {

MatX hexagon(double r) {
  MatX a(6, 2);
  for (int k = 0; k < 6; ++k) {
    a(k, 0) = r * std::cos(k * kPi / 3.0);
    a(k, 1) = r * std::sin(k * kPi / 3.0);
  }
  return a;
}

/// Six RTOA anchors on a 3 km hexagon, LOS N(0, 10), NLOS Rayleigh variance 5000 (Huerta Table X).
MeasurementStack rtoa_stack() {
  MeasurementStack st(ConstantVelocityClock2::layout(), hexagon(3000.0), 2);
  for (int b = 0; b < 6; ++b)
    st.add_rtoa(b, {noise::Normal(0.0, std::sqrt(10.0)), noise::Rayleigh::from_variance(5000.0)});
  return st;
}

/// RTOA measurements of position p, clock tau, plus bias[b] and N(0, sigma^2) noise.
VecX rtoa(const MatX& anchors, const Vec<2>& p, double tau, const VecX& bias, double sigma, Rng& rng) {
  VecX y(anchors.rows());
  for (Eigen::Index b = 0; b < anchors.rows(); ++b)
    y[b] = (p - anchors.row(b).transpose()).norm() + tau + bias[b] + sigma * rng.normal();
  return y;
}

}  // namespace

TEST_CASE("LosSolver: exact TOA and RTOA data give the true position and clock", "[snapshot]") {
  const Vec<2> p(123.0, -456.0);
  SECTION("TOA, 3 anchors, 2 unknowns") {
    MatX a(3, 2);
    a << 0, 0, 1000, 0, 0, 1000;
    MeasurementStack st(ConstantVelocity2::layout(), a, 2);
    for (int b = 0; b < 3; ++b) st.add_toa(b, {noise::Normal(0.0, 1.0), noise::Normal(0.0, 1.0)});
    LosSolver s(st);
    REQUIRE(s.unknowns() == 2);
    REQUIRE_FALSE(s.has_clock());
    VecX y(3);
    for (int b = 0; b < 3; ++b) y[b] = (p - a.row(b).transpose()).norm();
    Theta lin;
    std::vector<char> use(3, 1);
    REQUIRE(s.linear_start(y, use, lin));
    CHECK_THAT(lin[0], WithinAbs(p[0], 1e-6));
    CHECK_THAT(lin[1], WithinAbs(p[1], 1e-6));
    const Fix f = s.solve_los(y, Theta::Zero(2));
    REQUIRE(f.converged);
    CHECK_THAT(f.theta[0], WithinAbs(p[0], 1e-5));
    CHECK_THAT(f.theta[1], WithinAbs(p[1], 1e-5));
    CHECK(f.cost < 1e-12);
  }
  SECTION("RTOA, 6 anchors, clock bias as third unknown") {
    const MeasurementStack st = rtoa_stack();
    LosSolver s(st);
    REQUIRE(s.unknowns() == 3);
    REQUIRE(s.has_clock());
    Rng rng(1);
    const VecX y = rtoa(st.anchors(), p, 7.5, VecX::Zero(6), 0.0, rng);
    Theta lin;
    std::vector<char> use(6, 1);
    REQUIRE(s.linear_start(y, use, lin));
    CHECK_THAT(lin[2], WithinAbs(7.5, 1e-6));
    Theta start(3);
    start << 500.0, 500.0, 0.0;
    const Fix f = s.solve_los(y, start);
    REQUIRE(f.converged);
    CHECK_THAT(f.theta[0], WithinAbs(p[0], 1e-5));
    CHECK_THAT(f.theta[1], WithinAbs(p[1], 1e-5));
    CHECK_THAT(f.theta[2], WithinAbs(7.5, 1e-5));
  }
  SECTION("a split-normal row pulls the fix by its mode") {
    const MeasurementStack st = rtoa_stack();
    LosSolver s(st);
    Rng rng(2);
    VecX bias = VecX::Zero(6);
    bias[0] = 100.0;
    const VecX y = rtoa(st.anchors(), p, 0.0, bias, 0.0, rng);
    std::vector<RowNoise> nz = s.los_noise();
    nz[0] = RowNoise{100.0, 5.0, 50.0};  // mode at the true bias
    const Fix f = s.solve(y, Theta::Zero(3), std::vector<char>(6, 1), nz);
    CHECK_THAT(f.theta[0], WithinAbs(p[0], 1e-4));
    CHECK_THAT(f.theta[1], WithinAbs(p[1], 1e-4));
  }
}

TEST_CASE("LosSolver: argument checks name the argument", "[snapshot]") {
  const MeasurementStack st = rtoa_stack();
  LosSolver s(st);
  CHECK_THROWS_WITH(s.solve(VecX::Zero(5), Theta::Zero(3), std::vector<char>(6, 1), s.los_noise()),
                    Catch::Matchers::Contains("y"));
  CHECK_THROWS_WITH(s.solve(VecX::Zero(6), Theta::Zero(2), std::vector<char>(6, 1), s.los_noise()),
                    Catch::Matchers::Contains("theta0"));
  CHECK_THROWS_WITH(Chen(st, ChenOptions{-1, 1.0}), Catch::Matchers::Contains("reject_fraction"));
  // inf was taken: every weight 1 / inf = 0 gave a NaN fix marked valid, and an infinite step tolerance
  // ended each solve after one step, reported converged
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(Chen(st, ChenOptions{-1, 0.5, inf}), "opt.residual_floor: expected a finite value > 0");
  CHECK_THROWS_WITH(LosSolver(st, GaussNewtonOptions{30, inf}),
                    "opt.step_tolerance: expected a finite value > 0");
  CHECK_THROWS_WITH(MleLos(st, GaussNewtonOptions{30, std::nan("")}),
                    "opt.step_tolerance: expected a finite value > 0");
  CHECK_THROWS_WITH(subsets_at_least(21, 1), Catch::Matchers::Contains("num_anchors"));
  // a start that is not finite: refused by every snapshot estimator's reset, naming it
  const Theta bad = (Theta(3) << 0.0, std::nan(""), 0.0).finished();
  const std::string msg = "start: expected finite values (no NaN or inf)";
  CHECK_THROWS_WITH(MleLos(st).reset(bad), msg);
  CHECK_THROWS_WITH(Chen(st).reset(bad), msg);
  CHECK_THROWS_WITH(Cong(st).reset(bad), msg);
}

TEST_CASE("LosSolver and MleLos: short y / use / noise are rejected before any row is read", "[snapshot]") {
  const MeasurementStack st = rtoa_stack();
  LosSolver s(st);
  const VecX y5 = VecX::Zero(5), y6 = VecX::Constant(6, 3000.0);
  const std::vector<char> use5(5, 1), use6(6, 1);
  Theta t;
  CHECK_THROWS_WITH(s.linear_start(y5, use6, t), "y: expected shape (6, 1), got (5, 1)");
  CHECK_THROWS_WITH(s.linear_start(y6, use5, t), "use: expected one flag per row (6), got 5");
  CHECK_THROWS_WITH(s.cost(y5, Theta::Zero(3), use6, s.los_noise()), "y: expected shape (6, 1), got (5, 1)");
  CHECK_THROWS_WITH(s.cost(y6, Theta::Zero(3), use5, s.los_noise()),
                    "use: expected one flag per row (6), got 5");
  const std::vector<RowNoise> noise5(5);
  CHECK_THROWS_WITH(s.cost(y6, Theta::Zero(3), use6, noise5),
                    "noise: expected one RowNoise per row (6), got 5");
  CHECK_THROWS_WITH(s.cost(y6, Theta::Zero(2), use6, s.los_noise()),
                    "theta: expected shape (3, 1), got (2, 1)");
  CHECK_THROWS_WITH(s.solve(y6, Theta::Zero(3), use6, noise5),
                    "noise: expected one RowNoise per row (6), got 5");
  VecX r;
  CHECK_THROWS_WITH(s.residuals(y5, Theta::Zero(3), r), "y: expected shape (6, 1), got (5, 1)");
  MleLos mle(st);
  CHECK_THROWS_WITH(mle.solve(y5), "y: expected shape (6, 1), got (5, 1)");
  // the checked cost is the sum of squared normalised residuals: y = 3000 + 1 on every row at the centre
  // (each anchor 3000 m away, clock 0), LOS sigma sqrt(10): 6 * 1 / 10
  CHECK_THAT(s.cost(VecX::Constant(6, 3001.0), Theta::Zero(3), use6, s.los_noise()), WithinAbs(0.6, 1e-9));
}

TEST_CASE("RowNoise: non-finite centres and non-positive sigmas are rejected", "[snapshot]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(RowNoise::gaussian(nan, 1.0), "RowNoise.center: expected a finite value, got nan");
  CHECK_THROWS_WITH(RowNoise::gaussian(0.0, 0.0),
                    "RowNoise.sigma_left: expected a finite value > 0, got 0.000000");
  CHECK_THROWS_WITH(RowNoise::gaussian(0.0, std::numeric_limits<double>::infinity()),
                    "RowNoise.sigma_left: expected a finite value > 0, got inf");
  CHECK(RowNoise::gaussian(1.0, 2.0).valid());
  CHECK_FALSE((RowNoise{0.0, 1.0, -1.0}.valid()));
  // solve() checks every row's model and names the row
  const MeasurementStack st = rtoa_stack();
  LosSolver s(st);
  const VecX y = VecX::Constant(6, 3000.0);
  std::vector<RowNoise> nz = s.los_noise();
  nz[3].sigma_right = nan;
  CHECK_THROWS_WITH(s.solve(y, Theta::Zero(3), std::vector<char>(6, 1), nz),
                    "noise[3].sigma_right: expected a finite value > 0, got nan");
  nz[3].sigma_right = 1.0;
  nz[4].center = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(s.solve(y, Theta::Zero(3), std::vector<char>(6, 1), nz),
                    "noise[4].center: expected a finite value, got inf");
  nz[4].center = 0.0;
  nz[0].sigma_left = 0.0;
  CHECK_THROWS_WITH(s.solve(y, Theta::Zero(3), std::vector<char>(6, 1), nz),
                    "noise[0].sigma_left: expected a finite value > 0, got 0.000000");
}

TEST_CASE("subsets_at_least enumerates larger sets first", "[snapshot]") {
  const auto v = subsets_at_least(6, 4);
  REQUIRE(v.size() == 22u);  // C(6,6) + C(6,5) + C(6,4)
  CHECK(v.front() == 0x3Fu);
  CHECK(mask_count(v.back()) == 4);
  CHECK(subsets_at_least(6, 3).size() == 42u);
}

TEST_CASE("MleLos: one anchor, range and array phase (H1 geometry) is the polar inversion", "[snapshot]") {
  MeasurementStack st(ConstantVelocity2::layout(), MatX::Zero(1, 2), 2);
  st.add_toa(0, {noise::Normal(0.0, std::sqrt(10.0)), noise::Rayleigh::from_variance(2000.0)});
  const double c = kPi / 2.0;
  st.add_aoa_phase(0, c, {noise::Normal(0.0, 3e-3), noise::Normal(0.0, 3e-2)});
  MleLos mle(st);
  const Vec<2> p(-300.0, 400.0);
  VecX y(2);
  y << p.norm(), kPi * std::sin(std::atan2(p[1], p[0]) - c);
  const SnapshotResult& r = mle.solve(y);
  REQUIRE(r.valid);
  CHECK_THAT(r.theta[0], WithinAbs(p[0], 1e-6));
  CHECK_THAT(r.theta[1], WithinAbs(p[1], 1e-6));
  // A missing phase leaves one equation for two unknowns: still a finite answer, not a crash.
  y[1] = std::numeric_limits<double>::quiet_NaN();
  CHECK(mle.solve(y).theta.allFinite());
}

TEST_CASE("CHEN: residual weighting follows the all-LOS combinations", "[snapshot]") {
  const MeasurementStack st = rtoa_stack();
  Chen chen(st);
  REQUIRE(chen.combinations().size() == 22u);
  const Vec<2> p(250.0, -100.0);
  VecX bias = VecX::Zero(6);
  bias[1] = 180.0;
  bias[4] = 260.0;
  Rng rng(3);
  double err_chen = 0.0, err_los = 0.0;
  MleLos mle(st);
  const int E = 20;
  for (int e = 0; e < E; ++e) {
    const VecX y = rtoa(st.anchors(), p, 3.0, bias, std::sqrt(10.0), rng);
    err_chen += (chen.solve(y).theta.head<2>() - p).norm() / E;
    err_los += (mle.solve(y).theta.head<2>() - p).norm() / E;
  }
  // Two NLOS anchors: all-anchor ML is pulled by tens of metres; CHEN stays near the LOS-only fix.
  CHECK(err_chen < 15.0);
  CHECK(err_los > 2.0 * err_chen);
}

TEST_CASE("CONG: residual test finds the LOS set, otherwise falls back to the split-normal rows",
          "[snapshot]") {
  const MeasurementStack st = rtoa_stack();
  Cong cong(st);
  // The fitted split normal of the Rayleigh (variance 5000): mode near the Rayleigh mode (scale 107.9).
  const RowNoise& a = cong.nlos_noise()[0];
  CHECK(a.center > 60.0);
  CHECK(a.center < 160.0);
  CHECK(a.sigma_right > a.sigma_left);
  const Vec<2> p(-400.0, 700.0);
  Rng rng(4);
  SECTION("four LOS anchors: found and used") {
    VecX bias = VecX::Zero(6);
    bias[0] = 150.0;
    bias[3] = 90.0;
    int right = 0;
    double err = 0.0;
    for (int e = 0; e < 20; ++e) {
      const VecX y = rtoa(st.anchors(), p, -2.0, bias, std::sqrt(10.0), rng);
      const SnapshotResult& r = cong.solve(y);
      REQUIRE(r.valid);
      VecXi truth(6);
      truth << 1, 0, 0, 1, 0, 0;
      right += cong.enough_los() && r.sight == truth;
      err += (r.theta.head<2>() - p).norm() / 20;
    }
    CHECK(right >= 18);
    CHECK(err < 15.0);
  }
  SECTION("only two LOS anchors: too few, every anchor declared NLOS") {
    VecX bias(6);
    bias << 150.0, 0.0, 120.0, 200.0, 0.0, 80.0;
    const VecX y = rtoa(st.anchors(), p, 0.0, bias, std::sqrt(10.0), rng);
    const SnapshotResult& r = cong.solve(y);
    REQUIRE(r.valid);
    CHECK_FALSE(cong.enough_los());
    CHECK(r.sight == VecXi::Ones(6));
    CHECK((r.theta.head<2>() - p).norm() < 300.0);
  }
}

TEST_CASE("URR: the trellis settles on the true LOS hypothesis", "[snapshot]") {
  const MeasurementStack st = rtoa_stack();
  UrruelaOptions o;
  o.nlos_span = 330.0;
  Urruela urr(st, o);
  REQUIRE(urr.hypotheses().size() == 42u);  // LOS sets of >= 3 anchors
  const Vec<2> p(600.0, 300.0);
  VecX bias = VecX::Zero(6);
  bias[2] = 140.0;
  bias[5] = 220.0;
  VecXi truth(6);
  truth << 0, 0, 1, 0, 0, 1;
  Rng rng(5);
  int right = 0;
  double err = 0.0;
  for (int e = 0; e < 30; ++e) {
    const VecX y = rtoa(st.anchors(), p, 4.0, bias, std::sqrt(10.0), rng);
    const SnapshotResult& r = urr.solve(y);
    REQUIRE(r.valid);
    if (e >= 10) {
      right += r.sight == truth;
      err += (r.theta.head<2>() - p).norm() / 20;
    }
  }
  CHECK(right >= 19);
  CHECK(err < 15.0);
  // Path metrics are normalised: the best is 0.
  double mn = 1e300;
  for (double d : urr.path_metrics()) mn = std::min(mn, d);
  CHECK_THAT(mn, WithinAbs(0.0, 1e-12));
}

namespace {
/// est rejects an infinite row with the shared message, and the rejected call changes nothing: its next
/// fix equals that of a twin that never saw the bad epoch (warm starts and trellis included).
template <class Est>
void check_rejects_inf(const MeasurementStack& st, const VecX& y, const VecX& y2) {
  Est est(st), twin(st);
  est.solve(y);
  twin.solve(y);
  VecX bad = y;
  bad[3] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(est.solve(bad), "y: expected finite values, or NaN for a missing row; got inf at row 3");
  const SnapshotResult a = est.solve(y2);
  const SnapshotResult b = twin.solve(y2);
  CHECK(a.theta == b.theta);
  CHECK(a.sight == b.sight);
  CHECK(a.valid == b.valid);
}
}  // namespace

TEST_CASE("snapshot estimators reject inf in y (NaN is a missing row) and keep their state", "[snapshot]") {
  const MeasurementStack st = rtoa_stack();
  Rng rng(8);
  VecX bias = VecX::Zero(6);
  bias[2] = 150.0;
  const VecX y = rtoa(st.anchors(), Vec<2>(100.0, 50.0), 1.0, bias, std::sqrt(10.0), rng);
  const VecX y2 = rtoa(st.anchors(), Vec<2>(110.0, 40.0), 1.0, bias, std::sqrt(10.0), rng);
  check_rejects_inf<MleLos>(st, y, y2);
  check_rejects_inf<Chen>(st, y, y2);
  check_rejects_inf<Cong>(st, y, y2);
  check_rejects_inf<Urruela>(st, y, y2);
  LosSolver s(st);
  VecX bad = y;
  bad[0] = -std::numeric_limits<double>::infinity();
  const std::vector<char> use(6, 1);
  CHECK_THROWS_WITH(s.cost(bad, Theta::Zero(3), use, s.los_noise()),
                    "y: expected finite values, or NaN for a missing row; got inf at row 0");
  CHECK_THROWS_WITH(s.solve(bad, Theta::Zero(3), use, s.los_noise()),
                    Catch::Matchers::Contains("got inf at row 0"));
  // NaN: the row is left out (a fix from the other five).
  VecX miss = y;
  miss[0] = std::nan("");
  MleLos mle(st);
  const SnapshotResult& r = mle.solve(miss);
  CHECK(r.valid);
  CHECK((r.theta.head<2>() - Vec<2>(100.0, 50.0)).norm() < 200.0);
}

TEST_CASE("snapshot baselines: options() returns the options they were built with", "[snapshot]") {
  // every field away from its default; CHEN, CONG and URR also pass the Gauss-Newton settings on to their
  // solver
  const MeasurementStack st = rtoa_stack();
  GaussNewtonOptions gn;
  gn.max_iterations = 7;
  gn.step_tolerance = 2.5e-3;
  gn.initial_damping = 3e-5;
  gn.max_damping = 4e8;
  auto same_gn = [&](const GaussNewtonOptions& o) {
    return o.max_iterations == 7 && o.step_tolerance == 2.5e-3 && o.initial_damping == 3e-5 &&
           o.max_damping == 4e8;
  };
  const LosSolver los(st, gn);
  CHECK(same_gn(los.options()));
  const MleLos mle(st, gn);
  CHECK(same_gn(mle.options()));
  CHECK(same_gn(mle.solver().options()));

  ChenOptions co;
  co.min_size = 5;
  co.reject_fraction = 0.3;
  co.residual_floor = 1e-6;
  const Chen chen(st, co, gn);
  CHECK(chen.options().min_size == 5);
  CHECK(chen.options().reject_fraction == 0.3);
  CHECK(chen.options().residual_floor == 1e-6);
  CHECK(same_gn(chen.solver().options()));

  CongOptions cg;
  cg.confidence = 0.95;
  cg.negative_sigmas = 2.5;
  cg.min_los = 5;
  cg.min_rows = 4;
  cg.fit_samples = 500;
  cg.fit_seed = 77;
  const Cong cong(st, cg, gn);
  CHECK(cong.options().confidence == 0.95);
  CHECK(cong.options().negative_sigmas == 2.5);
  CHECK(cong.options().min_los == 5);
  CHECK(cong.options().min_rows == 4);
  CHECK(cong.options().fit_samples == 500);
  CHECK(cong.options().fit_seed == 77);
  CHECK(same_gn(cong.solver().options()));

  UrruelaOptions uo;
  uo.p_nlos = 0.3;
  uo.p_ln = 0.01;
  uo.p_nl = 0.02;
  uo.nlos_span = 250.0;
  const Urruela urr(st, uo, gn);
  CHECK(urr.options().p_nlos == 0.3);
  CHECK(urr.options().p_ln == 0.01);
  CHECK(urr.options().p_nl == 0.02);
  CHECK(urr.options().nlos_span == 250.0);
  CHECK(same_gn(urr.solver().options()));
}
