// Scenarios H1 and H2 (Huerta et al. 2009 Sec. VI): draws reproducible and prefix-consistent, the measured
// NLOS fraction against eq. (18), geometry and noise of the draws, the parameter checks, and seeded accuracy
// (bounds about 1.3x the measured values) of the baselines and of the paper's IUKF and RBPFs on short runs.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/sim/h1.hpp"
#include "nlosloc/sim/h2.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/registry.hpp"

using namespace nlosloc;
using namespace nlosloc::sim;
using Catch::Matchers::WithinAbs;

namespace {
bool same(const RowMatX& a, const RowMatX& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         ((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all();
}
double nlos_fraction(const Scenario& s, int runs, int steps = 0) {
  double n = 0.0, tot = 0.0;
  for (int r = 0; r < runs; ++r) {
    const Draw d = s.draw("default", 7, static_cast<std::uint64_t>(r), steps);
    n += d.sight.cast<double>().sum();
    tot += static_cast<double>(d.sight.size());
  }
  return n / tot;
}
double p67(const MonteCarloResult& r, const std::string& name) {
  return percentile(pooled_errors(r.estimator(name).errors, r.discard), 67.0);
}
/// `runs` seeded runs of `steps` steps (0: the scenario's) of registered estimators on 2 threads.
MonteCarloResult seeded_runs(const std::string& scenario, std::uint64_t seed, int runs, int steps,
                             const std::vector<std::string>& names) {
  MonteCarloOptions opt;
  opt.runs = runs;
  opt.seed = seed;
  opt.threads = 2;
  opt.steps = steps;
  return run_monte_carlo(registry(), scenario, "default", names, opt);
}
}  // namespace

TEST_CASE("H1 and H2 are registered with the paper's estimators", "[h-scenarios]") {
  const Registry& reg = registry();
  REQUIRE(reg.has_scenario("H1"));
  REQUIRE(reg.has_scenario("H2"));
  const auto e1 = reg.estimators("H1");
  for (const char* n : {"MLE-LOS", "EKF-LOS"}) CHECK(std::find(e1.begin(), e1.end(), n) != e1.end());
  const auto e2 = reg.estimators("H2");
  for (const char* n : {"EKF-LOS", "CHEN", "CONG", "URR"})
    CHECK(std::find(e2.begin(), e2.end(), n) != e2.end());
  CHECK(reg.scenario("H1").choices().size() >= 6);
  CHECK(reg.scenario("H2").choices().size() >= 6);
}

TEST_CASE("H1/H2 draws are reproducible and a shorter draw is a prefix", "[h-scenarios]") {
  const H1 h1;
  const H2 h2;
  for (const Scenario* s : {static_cast<const Scenario*>(&h1), static_cast<const Scenario*>(&h2)}) {
    const Draw a = s->draw("default", 3, 5, 800), b = s->draw("default", 3, 5, 800);
    CHECK(same(a.y, b.y));
    CHECK(same(a.states, b.states));
    CHECK((a.sight.array() == b.sight.array()).all());
    CHECK(same(a.quality, b.quality));
    const Draw c = s->draw("default", 3, 5, 300);
    CHECK(same(c.y, RowMatX(a.y.topRows(300))));
    CHECK((c.sight.array() == a.sight.topRows(300).array()).all());
    CHECK(same(RowMatX(c.initial_mean.transpose()), RowMatX(a.initial_mean.transpose())));
    const Draw other = s->draw("default", 3, 6, 300);
    CHECK_FALSE(same(other.y, c.y));
  }
}

TEST_CASE("H1 geometry: constant velocity, one serving sector per step, NLOS fraction near eq. (18)",
          "[h-scenarios]") {
  const H1 h1;
  const Draw d = h1.draw("default", 1, 0);
  REQUIRE(d.steps() == 20000);
  CHECK_THAT(d.positions(0, 0), WithinAbs(-1000.0, 1e-9));
  CHECK_THAT(d.positions(19999, 0), WithinAbs(-1000.0 + 10.0 * 0.01 * 19999, 1e-6));
  CHECK_THAT(d.positions(19999, 1), WithinAbs(400.0, 1e-9));
  int changes = 0, prev = -1;
  for (int k = 0; k < d.steps(); ++k) {
    int present = 0, which = -1;
    for (int j = 0; j < 3; ++j)
      if (!std::isnan(d.y(k, 1 + j))) {
        ++present;
        which = j;
      }
    REQUIRE(present == 1);
    REQUIRE(!std::isnan(d.y(k, 0)));
    if (prev >= 0 && which != prev) ++changes;
    prev = which;
  }
  CHECK(changes == 2);  // 210 -> 90 -> 330 deg sectors (Fig. 10 discontinuities)
  // eq. (18): p_N = 5 / 35; measured over 40 runs of 200 s.
  const double f = nlos_fraction(h1, 40);
  CHECK(std::abs(f - 5.0 / 35.0) < 0.03);
}

TEST_CASE("H1 noise: LOS TOA error N(0, 10), NLOS error Rayleigh mean 85.6 m, quality Beta means",
          "[h-scenarios]") {
  const H1 h1;
  double e_los = 0, e2_los = 0, n_los = 0, e_nlos = 0, n_nlos = 0, o_los = 0, o_nlos = 0;
  for (int r = 0; r < 5; ++r) {
    const Draw d = h1.draw("default", 2, static_cast<std::uint64_t>(r));
    for (int k = 0; k < d.steps(); ++k) {
      const double e = d.y(k, 0) - d.positions.row(k).norm();
      if (d.sight(k, 0) == 0) {
        e_los += e;
        e2_los += e * e;
        o_los += d.quality(k, 0);
        ++n_los;
      } else {
        e_nlos += e;
        o_nlos += d.quality(k, 0);
        ++n_nlos;
      }
    }
  }
  REQUIRE(n_nlos > 1000);
  CHECK(std::abs(e_los / n_los) < 0.1);
  CHECK_THAT(e2_los / n_los, WithinAbs(10.0, 0.5));
  CHECK_THAT(e_nlos / n_nlos, WithinAbs(std::sqrt(2.0 * 2000.0 / (4.0 - kPi)) * std::sqrt(kPi / 2.0), 3.0));
  CHECK_THAT(o_los / n_los, WithinAbs(4.0 / 5.5, 0.01));
  CHECK_THAT(o_nlos / n_nlos, WithinAbs(1.5 / 5.5, 0.02));
}

TEST_CASE("H2 geometry and sight: hexagon, clock in the RTOA, NLOS fraction near 0.5", "[h-scenarios]") {
  const H2 h2;
  const MatX a = h2.anchors();
  REQUIRE(a.rows() == 6);
  for (int b = 0; b < 6; ++b) CHECK_THAT(a.row(b).norm(), WithinAbs(3000.0, 1e-9));
  CHECK_THAT((a.row(0) - a.row(1)).norm(), WithinAbs(3000.0, 1e-9));
  const Draw d = h2.draw("default", 4, 0, 2000);
  // LOS rows: y - ||p - q|| - tau ~ N(0, 10).
  double s = 0, s2 = 0, n = 0;
  for (int k = 0; k < d.steps(); ++k)
    for (int b = 0; b < 6; ++b)
      if (d.sight(k, b) == 0) {
        const double e = d.y(k, b) - (d.positions.row(k) - a.row(b)).norm() - d.states(k, 2);
        s += e;
        s2 += e * e;
        ++n;
      }
  CHECK(std::abs(s / n) < 0.3);
  CHECK_THAT(s2 / n, WithinAbs(10.0, 1.0));
  CHECK(std::abs(nlos_fraction(h2, 30, 3000) - 0.5) < 0.06);
  CHECK_THAT(h2.urr_switch_probability(0), WithinAbs(0.05 / 10.05, 1e-12));
  CHECK_THAT(h2.urr_switch_probability(1), WithinAbs(0.05 / 10.05, 1e-12));
  CHECK_THAT(h2.urr_nlos_span(), WithinAbs(327.5, 0.5));
}

TEST_CASE("H2 URR: eq. (15) switch probabilities use E{L_LOS} from LOS and E{L_NLOS} from NLOS",
          "[h-scenarios]") {
  H2Params p;
  p.mean_los = 10.0;
  p.mean_nlos = 40.0;
  const H2 h2(p);
  // w dt = 5 m/s * 0.01 s = 0.05 m
  CHECK_THAT(h2.urr_switch_probability(0), WithinAbs(0.05 / 10.05, 1e-15));
  CHECK_THAT(h2.urr_switch_probability(1), WithinAbs(0.05 / 40.05, 1e-15));
  CHECK_THROWS_WITH(h2.urr_switch_probability(2),
                    "condition: expected 0 (LOS -> NLOS) or 1 (NLOS -> LOS), got 2");
  const auto est = make_h2_urr(h2, 0);
  const auto& urr = dynamic_cast<const SnapshotEstimator<snapshot::Urruela>&>(*est).solver();
  CHECK_THAT(urr.options().p_ln, WithinAbs(0.05 / 10.05, 1e-15));
  CHECK_THAT(urr.options().p_nl, WithinAbs(0.05 / 40.05, 1e-15));
  CHECK_THAT(urr.options().p_nlos, WithinAbs(40.0 / 50.0, 1e-15));  // eq. (18)
}

TEST_CASE("H1Params / H2Params: every field is checked and named", "[h-scenarios]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  {
    H2Params p;
    p.tau0_var = -1.0;  // used to give NaN clock draws
    CHECK_THROWS_WITH(H2(p), "H2Params.tau0_var: expected a finite value > 0, got -1.000000");
  }
  {
    H2Params p;
    p.tau_dot0_var = nan;
    CHECK_THROWS_WITH(H2(p), "H2Params.tau_dot0_var: expected a finite value > 0, got nan");
  }
  {
    H2Params p;
    p.side = 0.0;
    CHECK_THROWS_WITH(H2(p), "H2Params.side: expected a finite value > 0, got 0.000000");
  }
  {
    H2Params p;
    p.mean_nlos = -2.0;  // named as the H2Params field, not as the sight model's argument
    CHECK_THROWS_WITH(H2(p), "H2Params.mean_nlos: expected a finite value > 0, got -2.000000");
  }
  {
    H2Params p;
    p.pf_particles = 0;
    CHECK_THROWS_WITH(H2(p), "H2Params.pf_particles: expected >= 1, got 0");
  }
  {
    H1Params p;
    p.initial_std[2] = -1.0;
    CHECK_THROWS_WITH(H1(p), "H1Params.initial_std[2]: expected a finite value > 0, got -1.000000");
  }
  {
    H1Params p;
    p.start[1] = nan;
    CHECK_THROWS_WITH(H1(p), "H1Params.start: expected finite values (no NaN or inf)");
  }
  {
    H1Params p;
    p.sector_deg[0] = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(H1(p), "H1Params.sector_deg: expected finite values (no NaN or inf)");
  }
  {
    H1Params p;
    p.toa_nlos_var = 0.0;
    CHECK_THROWS_WITH(H1(p), "H1Params.toa_nlos_var: expected a finite value > 0, got 0.000000");
  }
  CHECK_NOTHROW(H1(H1Params()));
  CHECK_NOTHROW(H2(H2Params()));
}

TEST_CASE("H1 baselines: seeded accuracy on short runs", "[h-scenarios]") {
  MonteCarloOptions opt;
  opt.runs = 4;
  opt.seed = 11;
  opt.threads = 2;
  opt.steps = 3000;
  const MonteCarloResult r = run_monte_carlo(registry(), "H1", "default", {"MLE-LOS", "EKF-LOS"}, opt);
  const double mle = p67(r, "MLE-LOS"), ekf = p67(r, "EKF-LOS");
  INFO("MLE-LOS p67 " << mle << ", EKF-LOS p67 " << ekf);
  CHECK(mle < 5.6);                                          // measured 4.28
  CHECK(ekf < 3.4);                                          // measured 2.60
  CHECK(r.estimator("MLE-LOS").sight_accuracy.size() == 0);  // MLE-LOS does not classify sight
}

TEST_CASE("H2 baselines: seeded accuracy on short runs, CONG/URR classify sight above the majority answer",
          "[h-scenarios]") {
  MonteCarloOptions opt;
  opt.runs = 4;
  opt.seed = 12;
  opt.threads = 2;
  opt.steps = 2000;  // 400 steps are too few: that draw is 72% NLOS and URR's trellis is still settling
  const MonteCarloResult r =
      run_monte_carlo(registry(), "H2", "default", {"EKF-LOS", "CHEN", "CONG", "URR"}, opt);
  // bounds about 1.3x the measured seeded p67 (m): EKF-LOS 56.3, CHEN 82.0, CONG 56.9, URR 110.2
  const std::vector<std::pair<const char*, double>> bound = {
      {"EKF-LOS", 73.0}, {"CHEN", 107.0}, {"CONG", 74.0}, {"URR", 143.0}};
  for (const auto& [n, b] : bound) {
    INFO(n << " p67 " << p67(r, n));
    CHECK(p67(r, n) < b);
  }
  CHECK(r.estimator("CHEN").sight_accuracy.size() == 0);  // CHEN weights, it does not classify
  // Always answering the condition most frequent in these draws scores 0.537 (NLOS fraction 0.463);
  // measured CONG 0.776, URR 0.750.
  double nlos = 0.0, total = 0.0;
  for (int run = 0; run < opt.runs; ++run) {
    const Draw d =
        registry().scenario("H2").draw("default", opt.seed, static_cast<std::uint64_t>(run), opt.steps);
    nlos += d.sight.cast<double>().sum();
    total += static_cast<double>(d.sight.size());
  }
  const double majority = std::max(nlos / total, 1.0 - nlos / total);
  for (const char* n : {"CONG", "URR"}) {
    const double acc = r.estimator(n).sight_anchor_accuracy.mean();
    INFO(n << " sight accuracy " << acc << ", majority answer " << majority);
    CHECK(acc > majority + 0.15);
  }
}

TEST_CASE("H1 Huerta estimators: rRBPF-8 and IUKF, seeded accuracy and ordering", "[h-scenarios]") {
  // the full 200 s: 0.5 to 1.5 s of wall time in Release on 2 cores (idle / shared machine)
  const MonteCarloResult r = seeded_runs("H1", 11, 4, 0, {"EKF-LOS", "IUKF", "rRBPF-8"});
  const double ekf = p67(r, "EKF-LOS"), iukf = p67(r, "IUKF"), rbpf = p67(r, "rRBPF-8");
  INFO("p67 EKF-LOS " << ekf << ", IUKF " << iukf << ", rRBPF-8 " << rbpf);
  // measured p67 (m): EKF-LOS 7.75, IUKF 0.58, rRBPF-8 0.54; bounds about 1.3x
  CHECK(rbpf < 0.70);
  CHECK(iukf < 0.75);
  CHECK(rbpf < ekf / 5.0);  // Sec. VI-A: tracking the sight beats assuming LOS by far
  CHECK(rbpf <= iukf);      // Fig. 13: RBPF at least as good as IUKF with one anchor
  // measured sight accuracy 0.9999 (rRBPF-8), 0.993 (IUKF); the majority answer (LOS) scores 0.845
  CHECK(r.estimator("rRBPF-8").sight_anchor_accuracy.mean() > 0.99);
  CHECK(r.estimator("IUKF").sight_anchor_accuracy.mean() > 0.98);
}

TEST_CASE("H2 Huerta estimators: IUKF and rRBPF-16, seeded accuracy and ordering", "[h-scenarios]") {
  // 30 s: 0.15 to 0.5 s of wall time in Release on 2 cores (idle / shared machine)
  const MonteCarloResult r = seeded_runs("H2", 13, 4, 3000, {"EKF-LOS", "IUKF", "rRBPF-16"});
  const double ekf = p67(r, "EKF-LOS"), iukf = p67(r, "IUKF"), rbpf = p67(r, "rRBPF-16");
  INFO("p67 EKF-LOS " << ekf << ", IUKF " << iukf << ", rRBPF-16 " << rbpf);
  // measured p67 (m): EKF-LOS 53.1, IUKF 0.98, rRBPF-16 0.79; bounds about 1.3x
  CHECK(rbpf < 1.03);
  CHECK(iukf < 1.27);
  CHECK(rbpf < ekf / 10.0);  // Figs. 14-15: EKF-LOS severely impaired
  CHECK(rbpf < iukf);        // Figs. 14-15: IUKF the least accurate of the proposed methods
  // measured sight accuracy 0.9996 (rRBPF-16), 0.996 (IUKF); the majority answer scores 0.533
  CHECK(r.estimator("rRBPF-16").sight_anchor_accuracy.mean() > 0.99);
  CHECK(r.estimator("IUKF").sight_anchor_accuracy.mean() > 0.98);
}

TEST_CASE("backdate inverts one prediction and refuses what is not a belief", "[h-scenarios]") {
  const ConstantVelocity2 mo(0.5, 2.0);
  const Gaussian<4> b(Vec<4>(1.0, 2.0, 3.0, 4.0), Mat<4, 4>(Vec<4>(100.0, 100.0, 25.0, 25.0).asDiagonal()));
  const Gaussian<4> a = backdate(mo, b);  // F a.mean = b.mean, F a.cov F^T + Q = b.cov
  CHECK((mo.F() * a.mean - b.mean).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((mo.F() * a.cov * mo.F().transpose() + mo.Q() - b.cov).cwiseAbs().maxCoeff() < 1e-9);
  // a NaN mean came back all NaN, and -P as a start (the fallback returns b itself)
  Gaussian<4> bad = b;
  bad.mean(2) = std::nan("");
  CHECK_THROWS_WITH(backdate(mo, bad), "belief.mean: expected finite values (no NaN or inf)");
  bad = b;
  bad.cov = -b.cov;
  CHECK_THROWS_WITH(backdate(mo, bad), "belief.cov: expected a symmetric positive definite matrix");
}
