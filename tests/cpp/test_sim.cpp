// Simulation: metrics against hand-computed values, scenario K1 draws (reproducibility, truth, NLOS bias),
// the Monte Carlo runner (identical draws, estimator streams, thread-count independence, progress,
// cancellation) and the K1 EKF accuracy.
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/sim/estimators.hpp"
#include "nlosloc/sim/k1.hpp"
#include "nlosloc/sim/k2.hpp"
#include "nlosloc/sim/k3.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/registry.hpp"
#include "nlosloc/sim/report.hpp"

using namespace nlosloc;
using namespace nlosloc::sim;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

template class nlosloc::sim::GaussianFilterEstimator<Ekf<ConstantVelocity2>>;

namespace {

/// Writes the true position plus (u, 0), u ~ N(0, 1) drawn once per run from the estimator's stream.
class TruthPlusNoise final : public Estimator {
 public:
  explicit TruthPlusNoise(std::string n) : name_(std::move(n)) {}
  std::string name() const override { return name_; }
  void reset(const Draw& d, Rng& rng) override {
    d_ = &d;
    u_ = rng.normal();
  }
  void step(int k, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>&,
            Eigen::Ref<VecX> p) override {
    // The runner feeds the draw's row k (no Catch2 assertion here: this runs on worker threads).
    if (y != d_->y.row(k).transpose()) throw std::runtime_error("y is not the draw's row k");
    p = d_->positions.row(k).transpose();
    p[0] += u_;
  }

 private:
  std::string name_;
  const Draw* d_ = nullptr;
  double u_ = 0.0;
};

EstimatorFactory make_k1_ekf_spec() {
  return [](const Scenario& s, int c) { return make_k1_ekf(dynamic_cast<const K1&>(s), c); };
}

EstimatorSpec truth_plus_noise(const std::string& name) {
  return {name, [name](const Scenario&, int) { return std::make_unique<TruthPlusNoise>(name); }};
}

class Throws final : public Estimator {
 public:
  std::string name() const override { return "throws"; }
  void reset(const Draw&, Rng&) override {}
  void step(int k, const Eigen::Ref<const VecX>&, const Eigen::Ref<const VecX>&, Eigen::Ref<VecX>) override {
    if (k == 5) throw std::runtime_error("estimator failed at step 5");
  }
};

}  // namespace

// ---- metrics ------------------------------------------------------------------------------------

TEST_CASE("percentile interpolates linearly between closest ranks like numpy", "[sim][metrics]") {
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};  // sorted 1 2 3 4, h = 3 q / 100
  CHECK(percentile(v, 0) == 1.0);
  CHECK(percentile(v, 100) == 4.0);
  CHECK_THAT(percentile(v, 50), WithinAbs(2.5, 1e-15));   // h = 1.5
  CHECK_THAT(percentile(v, 67), WithinAbs(3.01, 1e-12));  // h = 2.01 -> 3 + 0.01
  CHECK_THAT(percentile(v, 95), WithinAbs(3.85, 1e-12));  // h = 2.85 -> 3 + 0.85
  CHECK_THAT(percentile(v, 10), WithinAbs(1.3, 1e-12));   // h = 0.3
  CHECK(percentile({7.0}, 67) == 7.0);
  CHECK(std::isnan(percentile({}, 50)));
  CHECK(std::isnan(percentile({1.0, std::nan(""), 2.0}, 50)));      // numpy propagates NaN
  const auto ps = percentiles({10, 20, 30, 40, 50}, {50, 67, 95});  // h = 2, 2.68, 3.8
  CHECK(ps[0] == 30.0);
  CHECK_THAT(ps[1], WithinAbs(36.8, 1e-12));
  CHECK_THAT(ps[2], WithinAbs(48.0, 1e-12));
  CHECK_THROWS_AS(percentile(v, 101), std::invalid_argument);
  CHECK_THROWS_AS(percentile(v, -1), std::invalid_argument);
  // A rank next to an inf is returned as it is (numpy's a + (b - a) t gives inf * 0 = NaN at t = 0).
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(percentile({1.0, 3.0, inf}, 50) == 3.0);
  CHECK(percentile({1.0, 3.0, inf}, 100) == inf);
  CHECK(percentile({inf, inf}, 30) == inf);
  CHECK(percentile({1.0, 3.0, inf}, 75) == inf);  // between 3 and inf
  // between -inf and a finite rank: -inf (a + (b - a) t was -inf + inf = NaN)
  const auto lo = percentiles({-inf, 1.0, 2.0}, {0, 25, 50});
  CHECK(lo[0] == -inf);
  CHECK(lo[1] == -inf);
  CHECK(lo[2] == 1.0);
  CHECK(percentile({-inf, inf}, 50) == -inf);
}

TEST_CASE("ecdf sorts and assigns rank / n, subsampling keeps both ends", "[sim][metrics]") {
  const Ecdf e = ecdf({3.0, 1.0, 2.0});
  REQUIRE(e.x == std::vector<double>{1.0, 2.0, 3.0});
  CHECK_THAT(e.p[0], WithinAbs(1.0 / 3, 1e-15));
  CHECK_THAT(e.p[1], WithinAbs(2.0 / 3, 1e-15));
  CHECK(e.p[2] == 1.0);
  std::vector<double> v(101);
  for (int i = 0; i <= 100; ++i) v[static_cast<std::size_t>(i)] = 100 - i;  // 100 .. 0
  const Ecdf s = ecdf(v, 5);  // ranks 0, 25, 50, 75, 100 of 0..100
  REQUIRE(s.x == std::vector<double>{0, 25, 50, 75, 100});
  CHECK_THAT(s.p[2], WithinAbs(51.0 / 101, 1e-15));
  CHECK(s.p.back() == 1.0);
  CHECK(ecdf(v, 1000).x.size() == 101);
  CHECK_THROWS_AS(ecdf(v, 1), std::invalid_argument);
  // tied values: p = P(error <= x) counts every tie (it was the rank of each, 0.4 at the first 2)
  const Ecdf t = ecdf({3.0, 1.0, 2.0, 2.0, 5.0, std::nan("")});
  REQUIRE(t.p.size() == 6);
  CHECK_THAT(t.p[1], WithinAbs(3.0 / 6, 1e-15));
  CHECK_THAT(t.p[2], WithinAbs(3.0 / 6, 1e-15));
  CHECK_THAT(t.p[3], WithinAbs(4.0 / 6, 1e-15));
  CHECK_THAT(t.p[4], WithinAbs(5.0 / 6, 1e-15));
  CHECK(t.p[5] == 1.0);  // the NaN keeps its own rank
  const Ecdf same = ecdf(std::vector<double>(7, 4.0), 3);
  CHECK(same.p == std::vector<double>{1.0, 1.0, 1.0});
}

TEST_CASE("rmse over time, probability within a threshold, mean, pooled errors", "[sim][metrics]") {
  RowMatX e(2, 3);
  e << 3, 4, 1,  //
      4, 0, 1;
  const VecX r = rmse_over_time(e);  // Ke & Wu Sec. 6.1 RMSE_k
  CHECK_THAT(r[0], WithinAbs(std::sqrt(12.5), 1e-14));
  CHECK_THAT(r[1], WithinAbs(std::sqrt(8.0), 1e-14));
  CHECK_THAT(r[2], WithinAbs(1.0, 1e-15));
  const std::vector<double> v{1, 2, 3, 4};
  CHECK(probability_within(v, 2.5) == 0.5);
  CHECK(probability_within(v, 2.0) == 0.5);  // inclusive
  CHECK(probability_within(v, 0.5) == 0.0);
  CHECK(probability_within({1.0, std::nan("")}, 10) == 0.5);
  CHECK_THROWS_WITH(probability_within(v, std::nan("")), "threshold: expected a number, got NaN");
  CHECK(mean_of(v) == 2.5);
  CHECK(std::isnan(mean_of(std::vector<double>{})));
  CHECK(pooled_errors(e, 1) == std::vector<double>{4, 1, 0, 1});
  CHECK_THROWS_AS(pooled_errors(e, 3), std::invalid_argument);
}

// ---- K1 draws -----------------------------------------------------------------------------------

TEST_CASE("K1 draws are reproducible from (seed, run) and differ between runs", "[sim][k1]") {
  const K1 k1;
  const Draw a = k1.draw("2LOS/1NLOS", 7, 3);
  const Draw b = k1.draw("2LOS/1NLOS", 7, 3);
  REQUIRE(a.steps() == 2000);
  CHECK(a.states.rows() == 2000);
  CHECK(a.states.cols() == 4);
  CHECK(a.positions.cols() == 2);
  CHECK(a.y.cols() == 3);
  CHECK(a.sight.cols() == 3);
  CHECK(a.quality.rows() == 2000);
  CHECK(a.quality.array().isNaN().all());  // K1 has no quality statistic
  CHECK(a.states == b.states);
  CHECK(a.y == b.y);
  CHECK(a.initial_mean == b.initial_mean);
  CHECK(a.initial_cov == b.initial_cov);
  const Draw c = k1.draw("2LOS/1NLOS", 7, 4);
  const Draw s = k1.draw("2LOS/1NLOS", 8, 3);
  CHECK((a.y - c.y).cwiseAbs().minCoeff() > 0.0);
  CHECK((a.y - s.y).cwiseAbs().minCoeff() > 0.0);
  CHECK(a.initial_mean != c.initial_mean);
  // A shorter draw is the prefix of the longer one.
  const Draw p = k1.draw("2LOS/1NLOS", 7, 3, 300);
  REQUIRE(p.steps() == 300);
  CHECK(p.y == a.y.topRows(300));
  CHECK(p.states == a.states.topRows(300));
  CHECK_THROWS_WITH(k1.draw("3LOS", 1, 0), Contains("3LOS/0NLOS"));
}

TEST_CASE("K1 sight: the last j nodes are NLOS in the case with j NLOS nodes", "[sim][k1]") {
  const K1 k1;
  const std::vector<std::string> cs = k1.cases();
  REQUIRE(cs.size() == 4);
  for (int c = 0; c < 4; ++c) {
    const Draw d = k1.draw(cs[static_cast<std::size_t>(c)], 1, 0, 10);
    for (int b = 0; b < 3; ++b) CHECK((d.sight.col(b).array() == (b >= 3 - c ? 1 : 0)).all());
  }
}

TEST_CASE("K1 truth follows the (10, 15) m/s line within the process-noise spread", "[sim][k1]") {
  const K1 k1;
  const auto& F = k1.motion().F();
  const auto& Q = k1.motion().Q();  // Ke & Wu eq. (16), variance 1
  for (std::uint64_t run = 0; run < 5; ++run) {
    const Draw d = k1.draw("3LOS/0NLOS", 11, run);
    CHECK(d.states.row(0) == (Eigen::RowVector4d() << 1000, 1000, 10, 15).finished());
    Mat<4, 4> P = Mat<4, 4>::Zero();  // covariance of the deviation from the noise-free line
    for (int k = 0; k < d.steps(); ++k) {
      if (k > 0) P = F * P * F.transpose() + Q;
      const double t = k * k1.dt();
      const Vec<4> line(1000 + 10 * t, 1000 + 15 * t, 10, 15);
      const Vec<4> dev = d.states.row(k).transpose() - line;
      for (int i = 0; i < 4; ++i) REQUIRE(std::abs(dev[i]) <= 5.0 * std::sqrt(P(i, i)) + 1e-9);
      REQUIRE(d.positions.row(k) == d.states.row(k).head<2>());
    }
  }
  // ... and the spread is there (the bound above also holds for a noise-free line): the velocity
  // increments v_k - v_k-1 = dt a_k have variance Q(2, 2) = dt^2 (eq. 16); 2000 of them, seeded.
  double ss = 0.0;
  int n = 0;
  for (std::uint64_t run = 0; run < 5; ++run) {
    const Draw d = k1.draw("3LOS/0NLOS", 201, run);
    for (int k = 1; k < d.steps(); ++k)
      for (int i = 2; i < 4; ++i, ++n) ss += std::pow(d.states(k, i) - d.states(k - 1, i), 2);
  }
  const double ratio = ss / n / Q(2, 2);
  INFO("sample variance / Q(2, 2) = " << ratio);
  CHECK(ratio > 0.85);
  CHECK(ratio < 1.15);
}

TEST_CASE("K1 measurement errors: LOS ~ N(0, 50^2), NLOS bias mean ~ 513", "[sim][k1]") {
  const K1 k1;
  const MatX q = k1.anchors();
  const Draw d = k1.draw("1LOS/2NLOS", 5, 2);  // nodes 1, 2 NLOS
  const int T = d.steps();
  for (int b = 0; b < 3; ++b) {
    VecX err(T);
    for (int k = 0; k < T; ++k) err[k] = d.y(k, b) - (d.positions.row(k) - q.row(b)).norm();
    const double mean = err.mean();
    const double sd = std::sqrt((err.array() - mean).square().sum() / (T - 1));
    if (b == 0) {
      CHECK(std::abs(mean) < 5.0 * 50.0 / std::sqrt(T));
      CHECK_THAT(sd, WithinRel(50.0, 0.1));
    } else {
      const double sd_true = std::hypot(50.0, 436.0);  // n + b
      CHECK(std::abs(mean - 513.0) < 5.0 * sd_true / std::sqrt(T));
      CHECK_THAT(sd, WithinRel(sd_true, 0.1));
    }
  }
}

TEST_CASE("K1 initial belief and stack", "[sim][k1]") {
  const K1 k1;
  CHECK(k1.measurements().rows() == 3);
  CHECK(k1.measurements().num_conditions() == 2);
  CHECK(k1.measurements().noise(0, 0).variance() == 2500.0);
  CHECK_THAT(k1.measurements().noise(2, 1).mean(), WithinAbs(513.0, 1e-12));
  // Initial mean error over many runs: unbiased with std (50, 50, 10, 10).
  Vec<4> s = Vec<4>::Zero(), s2 = Vec<4>::Zero();
  const int n = 400;
  for (int r = 0; r < n; ++r) {
    const Draw d = k1.draw("3LOS/0NLOS", 3, static_cast<std::uint64_t>(r), 101);
    const Vec<4> e = d.initial_mean - d.states.row(0).transpose();
    s += e;
    s2 += e.cwiseProduct(e);
    CHECK(d.initial_cov == Vec<4>(2500, 2500, 100, 100).asDiagonal().toDenseMatrix());
  }
  const Vec<4> sd(50, 50, 10, 10);
  for (int i = 0; i < 4; ++i) {
    CHECK(std::abs(s[i] / n) < 5.0 * sd[i] / std::sqrt(n));
    CHECK_THAT(std::sqrt(s2[i] / n), WithinRel(sd[i], 0.15));
  }
  // Paper Table 1 is stored in full (all three estimators).
  CHECK(k1.paper_value("EKF", "2LOS/1NLOS", "p67") == 309.2);
  CHECK(k1.paper_value("proposed", "0LOS/3NLOS", "p95") == 76.58);
  CHECK(k1.paper_value("iterated-NLOS-EKF", "1LOS/2NLOS", "p67") == 238.5);
  CHECK(!k1.paper_value("UKF", "2LOS/1NLOS", "p67"));
}

// ---- registry and runner ------------------------------------------------------------------------

TEST_CASE("registry names K1 and its EKF, and rejects unknown names", "[sim][registry]") {
  const Registry& reg = registry();
  REQUIRE(reg.has_scenario("K1"));
  const std::vector<std::string> k1_est = reg.estimators("K1");  // issue #4 adds proposed, iterated
  CHECK(std::find(k1_est.begin(), k1_est.end(), "EKF") != k1_est.end());
  CHECK_THROWS_WITH(reg.scenario("K9"), Contains("K1"));
  CHECK_THROWS_WITH(reg.estimator("K1", "UKF"), Contains("EKF"));
  MonteCarloOptions o;
  o.runs = 1;
  CHECK_THROWS_AS(run_monte_carlo(reg, "K1", "nope", {}, o), std::invalid_argument);
  CHECK_THROWS_AS(run_monte_carlo(reg, "K1", "3LOS/0NLOS", {"UKF"}, o), std::invalid_argument);
  Registry r2;
  register_k1(r2);
  CHECK_THROWS_AS(register_k1(r2), std::invalid_argument);  // duplicate names
}

TEST_CASE("runner feeds identical draws to every estimator and seeds them per (seed, name, run)",
          "[sim][montecarlo]") {
  const K1 k1;
  MonteCarloOptions o;
  o.runs = 5;
  o.seed = 42;
  o.steps = 150;
  o.threads = 2;
  const auto r = run_monte_carlo(k1, "2LOS/1NLOS", {truth_plus_noise("a"), truth_plus_noise("b")}, o);
  REQUIRE(r.estimators.size() == 2);
  CHECK(r.steps == 150);
  CHECK(r.discard == 100);
  CHECK(estimator_seed(42, "a") != estimator_seed(42, "b"));
  CHECK(estimator_seed(42, "a") != 42);
  for (int run = 0; run < 5; ++run)
    for (const char* name : {"a", "b"}) {
      Rng rng(estimator_seed(42, name), static_cast<std::uint64_t>(run));
      const double u = std::abs(rng.normal());
      const auto& e = r.estimator(name).errors;
      REQUIRE(e.rows() == 5);
      CHECK(((e.row(run).array() - u).abs() < 1e-9).all());  // ||(p + (u, 0)) - p|| = |u|
    }
  // The stream of "a" does not depend on what runs beside it.
  const auto r1 = run_monte_carlo(k1, "2LOS/1NLOS", {truth_plus_noise("a")}, o);
  CHECK(r1.estimator("a").errors == r.estimator("a").errors);
  CHECK((r.estimator("a").time_per_step_ns.array() > 0).all());
}

TEST_CASE("runner first_run: runs first_run.. equal the same rows of a run from 0", "[sim][montecarlo]") {
  const K1 k1;
  const EstimatorSpec ekf{"EKF", make_k1_ekf_spec()};
  MonteCarloOptions o;
  o.runs = 6;
  o.seed = 5;
  o.steps = 110;
  o.threads = 2;
  const auto full = run_monte_carlo(k1, "2LOS/1NLOS", {ekf, truth_plus_noise("a")}, o);
  CHECK(full.first_run == 0);
  o.runs = 3;
  o.first_run = 2;
  o.threads = 1;
  const auto part = run_monte_carlo(k1, "2LOS/1NLOS", {ekf, truth_plus_noise("a")}, o);
  CHECK(part.first_run == 2);
  REQUIRE(part.runs == 3);
  for (const char* name : {"EKF", "a"}) {
    const RowMatX rows = full.estimator(name).errors.middleRows(2, 3);
    CHECK(part.estimator(name).errors == rows);
  }
  CHECK(part.estimator("EKF").errors.minCoeff() > 0.0);  // the EKF rows are not the noise-free truth
  // The tables name the runs of a chunk, so a table of runs 2..4 does not read as one of runs 0..2.
  CHECK_THAT(format_percentile_table(summarize(k1, part)),
             StartsWith("K1 case 2LOS/1NLOS: 3 runs (runs 2..4) x 110 steps, errors over steps k >= "));
  CHECK_THAT(format_table(summarize(k1, full)), StartsWith("K1 case 2LOS/1NLOS: 6 runs x 110 steps, errors"));
  CHECK(summarize(k1, part).first_run == 2);
  // The last possible run, and one past it.
  o.runs = 1;
  o.first_run = std::numeric_limits<std::uint64_t>::max();
  CHECK(run_monte_carlo(k1, "2LOS/1NLOS", {ekf}, o).first_run == o.first_run);
  o.runs = 2;
  CHECK_THROWS_WITH(
      run_monte_carlo(k1, "2LOS/1NLOS", {ekf}, o),
      "first_run: expected first_run + runs - 1 <= 2^64 - 1, got first_run 18446744073709551615 "
      "and runs 2");
}

TEST_CASE("runner results are bit-identical for 1 and 2 threads", "[sim][montecarlo]") {
  const Registry& reg = registry();
  MonteCarloOptions o;
  o.runs = 6;
  o.seed = 9;
  o.steps = 400;
  o.threads = 1;
  const auto a = run_monte_carlo(reg, "K1", "1LOS/2NLOS", {}, o);
  o.threads = 2;
  const auto b = run_monte_carlo(reg, "K1", "1LOS/2NLOS", {}, o);
  CHECK(a.threads == 1);
  CHECK(b.threads == 2);
  CHECK(a.estimator("EKF").errors == b.estimator("EKF").errors);
  o.threads = 16;  // capped at the number of runs
  CHECK(run_monte_carlo(reg, "K1", "1LOS/2NLOS", {}, o).threads == 6);
}

TEST_CASE("runner progress, errors and cancellation", "[sim][montecarlo]") {
  const K1 k1;
  MonteCarloOptions o;
  o.runs = 7;
  o.steps = 120;
  std::vector<int> seen;
  o.progress = [&seen](int done, int total) {
    REQUIRE(total == 7);
    seen.push_back(done);
  };
  run_monte_carlo(k1, "3LOS/0NLOS", {truth_plus_noise("a")}, o);
  REQUIRE(!seen.empty());
  CHECK(seen.back() == 7);
  for (std::size_t i = 1; i < seen.size(); ++i) CHECK(seen[i] > seen[i - 1]);

  // An estimator that throws: the error reaches the caller.
  o.progress = nullptr;
  const EstimatorSpec bad{"throws", [](const Scenario&, int) { return std::make_unique<Throws>(); }};
  CHECK_THROWS_WITH(run_monte_carlo(k1, "3LOS/0NLOS", {truth_plus_noise("a"), bad}, o), Contains("step 5"));

  // A progress callback that throws cancels the run.
  o.runs = 50;
  o.progress = [](int done, int) {
    if (done >= 1) throw std::runtime_error("cancelled");
  };
  CHECK_THROWS_WITH(run_monte_carlo(k1, "3LOS/0NLOS", {truth_plus_noise("a")}, o), Contains("cancelled"));
  o.progress = nullptr;
  o.runs = 0;
  CHECK_THROWS_AS(run_monte_carlo(k1, "3LOS/0NLOS", {truth_plus_noise("a")}, o), std::invalid_argument);
  // Results are keyed by name: a repeated estimator is refused, not run twice with one kept.
  o.runs = 1;
  CHECK_THROWS_WITH(run_monte_carlo(k1, "3LOS/0NLOS", {truth_plus_noise("a"), truth_plus_noise("a")}, o),
                    "estimators: 'a' appears more than once");
  // Every statistic leaves out the first discard steps: a run no longer than that has none.
  o.steps = 100;
  CHECK_THROWS_WITH(run_monte_carlo(k1, "3LOS/0NLOS", {truth_plus_noise("a")}, o),
                    "steps: expected more than the scenario's 100 discarded first steps, got 100");
}

TEST_CASE("K1, K2 and K3 parameters are checked and the message names the field", "[sim][k1]") {
  K1Params p;
  p.start[0] = std::nan("");
  CHECK_THROWS_WITH(K1(p), "K1Params.start: expected finite values (no NaN or inf)");
  p = K1Params();
  p.initial_std[2] = 0.0;
  CHECK_THROWS_WITH(K1(p), Contains("K1Params.initial_std[2]: expected a finite value > 0"));
  p = K1Params();
  p.sigma_los = std::nan("");
  CHECK_THROWS_WITH(K1(p), Contains("K1Params.sigma_los"));
  p = K1Params();
  p.gamma = std::nan("");
  CHECK_THROWS_WITH(K1(p), Contains("K1Params.gamma: expected a finite value >= 1"));
  p = K1Params();
  p.iterated_iterations = 0;
  CHECK_THROWS_WITH(K1(p), "K1Params.iterated_iterations: expected >= 1, got 0");
  K2Params q;
  q.base.velocity[1] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(K2(q), Contains("K2Params.base.velocity"));
  K3Params r;
  r.sigma_rel = -1.0;
  CHECK_THROWS_WITH(K3(r), Contains("K3Params.sigma_rel: expected a finite value > 0"));
  r = K3Params();
  r.start = Vec<2>(100.0, 100.0);  // on an anchor: its noise std 0.02 d would be 0
  CHECK_THROWS_WITH(K3(r), "K3Params.start: expected a point away from every anchor");
  r = K3Params();
  r.iterated_bias_prior_std = std::nan("");
  CHECK_THROWS_WITH(K3(r), Contains("K3Params.iterated_bias_prior_std"));
  CHECK_NOTHROW(K1());
  CHECK_NOTHROW(K2());
  CHECK_NOTHROW(K3());
}

TEST_CASE("K1 EKF: 67% error below 25 m with three LOS nodes", "[sim][k1][ekf]") {
  const Registry& reg = registry();
  MonteCarloOptions o;
  o.runs = 4;
  o.seed = 1;
  const auto r = run_monte_carlo(reg, "K1", "3LOS/0NLOS", {"EKF"}, o);
  REQUIRE(r.steps == 2000);
  const auto& e = r.estimator("EKF").errors;
  REQUIRE(e.rows() == 4);
  REQUIRE(e.allFinite());
  const double p67 = percentile(pooled_errors(e, r.discard), 67);
  CHECK(p67 < 25.0);  // paper Table 1: 9.83 m
  CHECK(p67 > 1.0);

  // The report puts the paper's numbers beside ours.
  const CaseSummary s = summarize(reg.scenario("K1"), r);
  REQUIRE(s.estimators.size() == 1);
  CHECK_THAT(s.estimators[0].at(67), WithinAbs(p67, 1e-12));
  CHECK(s.estimators[0].paper_p67 == 9.83);
  CHECK(s.estimators[0].paper_p95 == 38.39);
  const std::string table = format_table(s);
  CHECK_THAT(table, Contains("EKF") && Contains("9.83") && Contains("38.39"));
  CHECK_THAT(format_choices(reg.scenario("K1")), Contains("(1000, 1000)"));
}
