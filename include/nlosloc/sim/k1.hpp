#pragma once
/// \file k1.hpp
/// Scenario K1 of reference/scenarios.md: Ke & Wu 2011 (papers/ke-wu2011-qp-ekf.md) Sec. 6.1, fixed
/// LOS/NLOS, large scale; and the K1 estimators of Ke & Wu Table 1: "proposed" (QP bias EKF,
/// mitigation/qp_bias_ekf.hpp), "iterated-NLOS-EKF" (bias-augmented EKF, mitigation/bias_augmented_ekf.hpp)
/// and "EKF". Also the Estimator adapters of the mitigation trackers, shared by K2 and K3.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/mitigation/bias_augmented_ekf.hpp"
#include "nlosloc/mitigation/box_qp_proxsuite.hpp"
#include "nlosloc/mitigation/qp_bias_ekf.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"
#include "nlosloc/models/noise.hpp"
#include "nlosloc/sim/estimators.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::sim {

/// Shared truth draw of K1-K3: the initial belief (mean = truth + initial_std noise, drawn first so a
/// shorter run is a prefix of a longer one) and the diagonal initial covariance.
template <class D>
void ke_wu_initial_belief(const Vec<4>& x, const Vec<4>& initial_std, Rng& rng, D& d) {
  d.initial_mean.resize(4);
  for (int i = 0; i < 4; ++i) d.initial_mean[i] = x[i] + initial_std[i] * rng.normal();
  d.initial_cov = initial_std.array().square().matrix().asDiagonal();
}
/// Ke & Wu eqs. (16)-(17): S(k) = Phi S(k-1) + Gamma W(k), W ~ N(0, diag(sigma_x^2, sigma_y^2)) with
/// sigma = sa (m/s^2).
inline void ke_wu_advance(const ConstantVelocity2& motion, double sa, double dt, Rng& rng, Vec<4>& x) {
  const double ax = sa * rng.normal(), ay = sa * rng.normal();
  x = motion.F() * x;
  x[0] += 0.5 * dt * dt * ax;
  x[1] += 0.5 * dt * dt * ay;
  x[2] += dt * ax;
  x[3] += dt * ay;
}

/// Checks of the fields K1Params and K3Params share (same names in both); messages name "<params>.<field>".
template <class P>
void check_ke_wu_params(const P& p, const std::string& params) {
  const auto field = [&](const char* f) { return params + "." + f; };
  NLOSLOC_ENSURE(p.steps > p.discard && p.discard >= 0,
                 params + ": expected 0 <= discard < steps, got discard " + std::to_string(p.discard) +
                     ", steps " + std::to_string(p.steps));
  nlosloc::detail::ensure_finite(p.start, field("start").c_str());
  nlosloc::detail::ensure_finite(p.velocity, field("velocity").c_str());
  nlosloc::detail::ensure_nonnegative(p.accel_var, field("accel_var").c_str());
  nlosloc::detail::ensure_positive(p.dt, field("dt").c_str());
  for (int i = 0; i < 4; ++i)  // > 0: the initial covariance diag(initial_std^2) must be SPD
    nlosloc::detail::ensure_positive(p.initial_std[i],
                                     (field("initial_std[") + std::to_string(i) + "]").c_str());
  NLOSLOC_ENSURE(p.gamma >= 1.0 && std::isfinite(p.gamma),
                 field("gamma") + ": expected a finite value >= 1 (eq. 32), got " + std::to_string(p.gamma));
  nlosloc::detail::ensure_positive(p.iterated_bias_prior_std, field("iterated_bias_prior_std").c_str());
  nlosloc::detail::ensure_nonnegative(p.iterated_bias_walk_std, field("iterated_bias_walk_std").c_str());
  NLOSLOC_ENSURE(p.iterated_iterations >= 1, field("iterated_iterations") + ": expected >= 1, got " +
                                                 std::to_string(p.iterated_iterations));
}

/// Parameters of K1; defaults are the paper's (Sec. 6 and 6.1) plus the choices listed by K1::choices().
struct K1Params {
  Mat<3, 2> anchors = (Mat<3, 2>() << 0, 0, 8600, 0, 4300, 7500).finished();  ///< Sec. 6, fixed nodes (m)
  double sigma_los = 50.0;                     ///< Sec. 6: TOA noise n_i ~ N(0, 50^2) (m)
  double nlos_mean = 513.0;                    ///< Sec. 6.1: NLOS error b_i ~ N(513, 436^2) (m)
  double nlos_std = 436.0;                     ///< Sec. 6.1
  Vec<2> start{1000.0, 1000.0};                ///< choice: start position (m)
  Vec<2> velocity{10.0, 15.0};                 ///< Sec. 6: (10, 15) m/s
  double accel_var = 1.0;                      ///< Sec. 6: sigma_x^2 = sigma_y^2 = 1 (m/s^2)^2, eq. (16)
  int steps = 2000;                            ///< Sec. 6: L = 2000 samples
  double dt = 0.1;                             ///< Sec. 6: Delta t = 0.1 s
  int discard = 100;                           ///< Sec. 6: first 100 samples left out
  Vec<4> initial_std{50.0, 50.0, 10.0, 10.0};  ///< choice: initial belief std (m, m, m/s, m/s)
  double gamma = 1.1;                          ///< Sec. 5: scaling factor of the NLOS test, eq. (32)
  double iterated_bias_prior_std = 500.0;      ///< choice: iterated NLOS EKF, prior std of each bias (m)
  double iterated_bias_walk_std = 1.0;         ///< choice: iterated NLOS EKF, bias random walk (m/step)
  int iterated_iterations = 1;                 ///< choice: iterated NLOS EKF, iterations of the update
  /// choice: b_i = max(0, N(513, 436^2)) (Sec. 2, eq. 1: "b_i(k) >= 0"); false: the plain normal draw,
  /// negative 12% of the time (issue #4 measured both; see K1::choices()).
  bool nlos_nonnegative = true;
};

/// K1: three TOA nodes, a mobile on a straight line with white-acceleration noise, 0..3 nodes in NLOS for
/// the whole run. Cases "3LOS/0NLOS", "2LOS/1NLOS", "1LOS/2NLOS", "0LOS/3NLOS"; the NLOS nodes of the case
/// with j NLOS nodes are the last j nodes (choice).
class K1 : public Scenario {
 public:
  /// Estimator names of Ke & Wu Table 1.
  static constexpr const char* kEkf = "EKF";
  static constexpr const char* kProposed = "proposed";
  static constexpr const char* kIterated = "iterated-NLOS-EKF";
  /// The proposed tracker with the soft threshold (qp_bias_ekf.hpp, item 4), and its lambda.
  static constexpr const char* kProposedSoft = "proposed-soft";
  static constexpr double kSoftThreshold = 1.0;

  /// Throws std::invalid_argument naming the first bad field ("K1Params.<field>: expected ...").
  explicit K1(const K1Params& p = K1Params())
      : p_(checked(p)),
        motion_(p.dt, p.accel_var, VelocityNoise::kWhiteAcceleration),
        stack_(make_stack(p)),
        bias_(p.nlos_mean, p.nlos_std),
        los_(0.0, p.sigma_los) {}

  /// `p` if every field is in range, else std::invalid_argument naming the field (`params`: the name to
  /// use, K2Params.base for K2). Runs before the members are built, so the message names the field
  /// rather than a model's argument.
  static const K1Params& checked(const K1Params& p, const std::string& params = "K1Params") {
    nlosloc::detail::ensure_finite(p.anchors, (params + ".anchors").c_str());
    nlosloc::detail::ensure_positive(p.sigma_los, (params + ".sigma_los").c_str());
    // > 0: NLOS adds a delay, and the filters' NLOS noise is a ShiftedNormal (shift > 0)
    nlosloc::detail::ensure_positive(p.nlos_mean, (params + ".nlos_mean").c_str());
    nlosloc::detail::ensure_positive(p.nlos_std, (params + ".nlos_std").c_str());
    check_ke_wu_params(p, params);
    return p;
  }

  std::string name() const override { return "K1"; }
  std::string description() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    return "Ke & Wu 2011 Sec. 6.1: 3 TOA nodes, fixed LOS/NLOS per node, NLOS error N(" + f(p_.nlos_mean) +
           ", " + f(p_.nlos_std) + "^2), mobile at " + detail::fmt_point(p_.velocity[0], p_.velocity[1]) +
           " m/s, L = " + std::to_string(p_.steps) + ", dt = " + f(p_.dt) + " s";
  }
  std::vector<std::string> choices() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    const K1Params& p = p_;
    const std::string r = f(p.sigma_los) + "^2";  // variance of n_i, R = r I
    const std::string bias = "N(" + f(p.nlos_mean) + ", " + f(p.nlos_std) + "^2)";
    // b ~ N(m, s^2) is negative with probability Phi(-m/s); E max(0, b) = m Phi(m/s) + s phi(m/s)
    const double z = p.nlos_mean / p.nlos_std;
    const double negative = 0.5 * std::erfc(z / std::sqrt(2.0));
    const double mean_b =
        p.nlos_mean * (1.0 - negative) + p.nlos_std * std::exp(-0.5 * z * z) / std::sqrt(2.0 * kPi);
    const std::string pct = detail::fmt_num(100.0 * negative, 2) + "%";
    const std::string stack = "N(" + f(p.nlos_mean) + ", " + r + " + " + f(p.nlos_std) + "^2)";
    std::string init;
    for (int i = 0; i < 4; ++i) init += (i > 0 ? ", " : "") + f(p.initial_std[i]) + "^2";
    const std::string updates =
        p.iterated_iterations == 1
            ? std::string(
                  "one EKF update per step (iterating the update, 2-3 Gauss-Newton passes, made every NLOS "
                  "case worse)")
            : std::to_string(p.iterated_iterations) +
                  " Gauss-Newton passes of the EKF update per step (one by default: 2-3 passes made every "
                  "NLOS case worse)";
    return {
        "start position " + detail::fmt_point(p.start[0], p.start[1]) +
            " m (scenarios.md choice); initial velocity exactly " +
            detail::fmt_point(p.velocity[0], p.velocity[1]) + " m/s",
        "truth simulated with the filters' model: eq. (16) white acceleration, variance " + f(p.accel_var) +
            " (m/s^2)^2 per axis",
        "NLOS nodes of a case with j NLOS nodes: the last j nodes (j = 1: " +
            detail::fmt_point(p.anchors(2, 0), p.anchors(2, 1)) + "; j = 2: also " +
            detail::fmt_point(p.anchors(1, 0), p.anchors(1, 1)) + ")",
        p.nlos_nonnegative
            ? "NLOS measurement = d + n + b with n ~ N(0, " + r + ") and b = max(0, " + bias +
                  ") drawn every step: Sec. 6.1's Gaussian with Sec. 2's b_i(k) >= 0 (eq. 1); a negative "
                  "draw (" +
                  pct + ") is an NLOS link with no excess delay (mean of b " + detail::fmt_num(mean_b, 3) +
                  " m). K1Params::nlos_nonnegative = false keeps the untruncated draw. The stack's NLOS row "
                  "noise (for the model-based filters) stays " +
                  stack
            : "NLOS measurement = d + n + b with n ~ N(0, " + r + ") and b ~ " + bias +
                  " drawn every step (K1Params::nlos_nonnegative = false: Sec. 6.1's Gaussian untruncated, "
                  "negative " +
                  pct +
                  " of the time although Sec. 2 has b_i(k) >= 0). The stack's NLOS row noise (for the "
                  "model-based filters) is " +
                  stack,
        "initial belief: mean = true state at k = 0 + N(0, diag(" + init +
            ")), drawn once per run and shared by all estimators; covariance diag(" + init + ")",
        "first update with y_0 at k = 0 (no prediction before it); 67% / 95% errors pooled over runs and "
        "samples k >= " +
            std::to_string(p.discard),
        "EKF: R = " + r + " I (LOS assumed on every node), Q of eq. (16) with variance " + f(p.accel_var) +
            ", no adaptive R (the paper's Ref. [19] adaptation is not specified)",
        "proposed: EKF + bias QP (Secs. 3-5), gamma = " + f(p.gamma) + ", R = " + r +
            " I (adaptive R of ref. [19] left out: form not given), bounds 0 <= b_i <= eq. (15) (upper < 0 "
            "clamped to 0); eqs. (12)-(14) referenced to the EKF prediction: r = innovation (eq. 26), L = I, "
            "Sigma_v = F P F^T + R (eq. 27), so the QP has a unique minimiser (Sec. 3's snapshot form has "
            "rank M - 2 and barely mitigates); rows whose bias lands strictly inside its box carry no "
            "information after subtraction and are left out of eqs. (22)-(25) that step; QP failure -> b = 0 "
            "(flagged); sight estimate of every node = the global decision of eq. (32)",
        "iterated-NLOS-EKF (Najar & Vidal 2003 as described in Ke & Wu Sec. 1 and in N&V's abstract: the "
        "Kalman filter's state includes one bias per node): bias random walk std " +
            f(p.iterated_bias_walk_std) + " m/step, bias prior N(0, " + f(p.iterated_bias_prior_std) +
            "^2), R = " + r + " I, " + updates + ", bias means projected onto >= 0",
        "proposed-soft: the proposed tracker with QpBiasEkfOptions::soft_threshold = 1 (not in the paper: an "
        "L1 term on eq. (14) so rows within about 1 standard deviation of the prediction stay LOS instead of "
        "being read as biased and left out; qp_bias_ekf.hpp item 4)",
    };
  }
  std::vector<std::string> cases() const override {
    return {"3LOS/0NLOS", "2LOS/1NLOS", "1LOS/2NLOS", "0LOS/3NLOS"};
  }
  int steps() const override { return p_.steps; }
  double dt() const override { return p_.dt; }
  MatX anchors() const override { return p_.anchors; }
  int discard() const override { return p_.discard; }
  int state_dim() const override { return ConstantVelocity2::kDim; }
  const MeasurementStack& measurements() const override { return stack_; }
  std::string paper_source() const override {
    return "Ke & Wu 2011, Table 1 (67% / 95% position error, m) and Table 2 (Matlab, Pentium IV: s per 2000 "
           "steps, given here as us per step)";
  }
  std::vector<PaperValue> paper() const override {
    // Ke & Wu 2011 Table 1: {proposed, iterated NLOS EKF, EKF} x {67%, 95%} per case.
    static const double t1[4][6] = {{17.17, 30.07, 34.58, 73.35, 9.83, 38.39},
                                    {32.76, 63.96, 105.8, 221.1, 309.2, 375.1},
                                    {35.99, 69.52, 238.5, 280.1, 789.9, 859.5},
                                    {37.37, 76.58, 301.9, 315.9, 828.5, 916.3}};
    // Ke & Wu 2011 Table 2: 0.352 s, 0.216 s, 0.191 s per 2000 steps.
    static const double t2[3] = {0.352, 0.216, 0.191};
    const char* est[3] = {kProposed, kIterated, kEkf};
    std::vector<PaperValue> v;
    const std::vector<std::string> cs = cases();
    for (int c = 0; c < 4; ++c)
      for (int e = 0; e < 3; ++e) {
        v.push_back({est[e], cs[static_cast<std::size_t>(c)], "p67", t1[c][2 * e]});
        v.push_back({est[e], cs[static_cast<std::size_t>(c)], "p95", t1[c][2 * e + 1]});
        v.push_back({est[e], cs[static_cast<std::size_t>(c)], "time_per_step_us", t2[e] / 2000.0 * 1e6});
      }
    // proposed-soft is our variant of the proposed tracker: compared with the same Table 1 column.
    for (int c = 0; c < 4; ++c) {
      v.push_back({kProposedSoft, cs[static_cast<std::size_t>(c)], "p67", t1[c][0]});
      v.push_back({kProposedSoft, cs[static_cast<std::size_t>(c)], "p95", t1[c][1]});
    }
    return v;
  }

  const K1Params& params() const { return p_; }
  /// Motion model of the truth and of the filters: Ke & Wu eq. (16).
  const ConstantVelocity2& motion() const { return motion_; }
  /// Number of NLOS nodes of case index c (cases are ordered 0, 1, 2, 3 NLOS nodes).
  static int nlos_count(int c) { return c; }
  /// True when anchor b is NLOS in case c (choice: the last nlos_count(c) nodes).
  static bool is_nlos(int c, int b) { return b >= 3 - nlos_count(c); }

 protected:
  void generate(int c, int T, Rng& rng, Draw& d) const override {
    constexpr int B = 3;
    d.states.resize(T, 4);
    d.positions.resize(T, 2);
    d.y.resize(T, B);
    d.sight.resize(T, B);
    d.quality.setConstant(T, B, std::numeric_limits<double>::quiet_NaN());  // K1 has no quality statistic

    Vec<4> x;
    x << p_.start, p_.velocity;
    // Initial belief first, so a shorter draw is a prefix of a longer one.
    ke_wu_initial_belief(x, p_.initial_std, rng, d);

    const double sa = std::sqrt(p_.accel_var), dt = p_.dt;
    for (int k = 0; k < T; ++k) {
      if (k > 0) ke_wu_advance(motion_, sa, dt, rng, x);  // Ke & Wu eqs. (16)-(17)
      d.states.row(k) = x.transpose();
      d.positions.row(k) = x.head<2>().transpose();
      for (int b = 0; b < B; ++b) {
        const bool nlos = is_nlos(c, b);
        // Ke & Wu eqs. (1)-(2): z_i = d_i + n_i + b_i, b_i = 0 in LOS.
        const double dist = (x.head<2>() - p_.anchors.row(b).transpose()).norm();
        double z = dist + los_.sample(rng);
        if (nlos) z += nlos_bias(rng);
        d.y(k, b) = z;
        d.sight(k, b) = nlos ? 1 : 0;
      }
    }
  }

  /// One NLOS excess delay b_i(k) of eq. (1): N(nlos_mean, nlos_std^2), floored at 0 when nlos_nonnegative.
  double nlos_bias(Rng& rng) const {
    const double b = bias_.sample(rng);
    return p_.nlos_nonnegative ? std::max(b, 0.0) : b;  // Ke & Wu Sec. 2: b_i(k) >= 0
  }

 private:
  static MeasurementStack make_stack(const K1Params& p) {
    MeasurementStack st(ConstantVelocity2::layout(), p.anchors, 2);
    // Condition 0: n ~ N(0, sigma_los^2); condition 1: n + b ~ N(nlos_mean, sigma_los^2 + nlos_std^2).
    for (int b = 0; b < 3; ++b)
      st.add_toa(b, {noise::Normal(0.0, p.sigma_los),
                     noise::ShiftedNormal(p.nlos_mean, std::hypot(p.sigma_los, p.nlos_std))});
    return st;
  }

  K1Params p_;
  ConstantVelocity2 motion_;
  MeasurementStack stack_;
  noise::ShiftedNormal bias_;  ///< b_i of eq. (1) in NLOS
  noise::Normal los_;          ///< n_i of eq. (1)
};

/// K1 "EKF": Ke & Wu's baseline EKF (eqs. 17-24) assuming LOS on every node (R = 50^2 I), motion eq. (16).
inline std::unique_ptr<Estimator> make_k1_ekf(const K1& s, int /*case_index*/) {
  return make_filter_estimator(K1::kEkf, Ekf<ConstantVelocity2>(s.motion(), s.measurements(), Gaussian<4>()),
                               SightPolicy::kAssumeLos);
}

/// Runs a mitigation::QpBiasEkf as an Estimator (the "proposed" tracker, or with options.mitigate = false
/// a plain EKF with the same range-noise model). With mitigation on it estimates sight: every anchor gets
/// the global decision of eq. (32) (1 = NLOS), the test being on the whole innovation vector.
class QpBiasEkfEstimator final : public Estimator {
 public:
  QpBiasEkfEstimator(std::string name, mitigation::QpBiasEkf tracker)
      : name_(std::move(name)), f_(std::move(tracker)) {}
  std::string name() const override { return name_; }
  void reset(const Draw& d, Rng& /*deterministic*/) override {
    detail::ensure_shape(d.initial_mean, 4, 1, "draw.initial_mean");
    detail::ensure_shape(d.initial_cov, 4, 4, "draw.initial_cov");
    f_.set_belief(Gaussian<4>(d.initial_mean, d.initial_cov), 0.0);
  }
  void step(int k, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& /*o*/,
            Eigen::Ref<VecX> position_out) override {
    if (k > 0) {
      f_.step(y);
    } else {
      f_.update(y);  // the initial belief is already at t_0
    }
    position_out = f_.mean().head<2>();
  }
  bool estimates_sight() const override { return f_.options().mitigate; }
  void sight_estimate(Eigen::Ref<VecXi> out) const override { out.setConstant(f_.nlos_detected() ? 1 : 0); }
  const mitigation::QpBiasEkf& tracker() const { return f_; }

 private:
  std::string name_;
  mitigation::QpBiasEkf f_;
};

/// Runs a mitigation::BiasAugmentedEkf (the "iterated NLOS EKF") as an Estimator.
class BiasAugmentedEkfEstimator final : public Estimator {
 public:
  BiasAugmentedEkfEstimator(std::string name, mitigation::BiasAugmentedEkf tracker)
      : name_(std::move(name)), f_(std::move(tracker)) {}
  std::string name() const override { return name_; }
  void reset(const Draw& d, Rng& /*deterministic*/) override {
    detail::ensure_shape(d.initial_mean, 4, 1, "draw.initial_mean");
    detail::ensure_shape(d.initial_cov, 4, 4, "draw.initial_cov");
    f_.set_belief(Gaussian<4>(d.initial_mean, d.initial_cov), 0.0);
  }
  void step(int k, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& /*o*/,
            Eigen::Ref<VecX> position_out) override {
    if (k > 0) {
      f_.step(y);
    } else {
      f_.update(y);
    }
    position_out = f_.mean().head<2>();
  }
  const mitigation::BiasAugmentedEkf& tracker() const { return f_; }

 private:
  std::string name_;
  mitigation::BiasAugmentedEkf f_;
};

/// Ke & Wu's QP-bias EKF (Secs. 3-5) on K1Params p (R = sigma_los^2 I, gamma), soft threshold lambda.
inline std::unique_ptr<Estimator> make_k1_qp_bias_ekf(const char* name, const K1Params& p,
                                                      const ConstantVelocity2& motion, double lambda) {
  mitigation::QpBiasEkfOptions o;
  o.gamma = p.gamma;
  o.noise.sigma0 = p.sigma_los;
  o.soft_threshold = lambda;
  return std::make_unique<QpBiasEkfEstimator>(name,
                                              mitigation::QpBiasEkf(motion, p.anchors, Gaussian<4>(), o));
}
/// K1 "proposed": Ke & Wu's QP-bias EKF (Secs. 3-5) with R = 50^2 I and gamma = 1.1.
inline std::unique_ptr<Estimator> make_k1_proposed(const K1& s, int /*case_index*/) {
  return make_k1_qp_bias_ekf(K1::kProposed, s.params(), s.motion(), 0.0);
}
/// K1 "proposed-soft": the same with the soft threshold lambda = 1 (qp_bias_ekf.hpp, item 4).
inline std::unique_ptr<Estimator> make_k1_proposed_soft(const K1& s, int /*case_index*/) {
  return make_k1_qp_bias_ekf(K1::kProposedSoft, s.params(), s.motion(), K1::kSoftThreshold);
}

/// K1 "iterated-NLOS-EKF": the bias-augmented iterated EKF (Najar & Vidal 2003, Ke & Wu Sec. 1).
inline std::unique_ptr<Estimator> make_k1_iterated(const K1& s, int /*case_index*/) {
  mitigation::BiasAugmentedEkfOptions o;
  o.noise.sigma0 = s.params().sigma_los;
  o.bias_prior_std = s.params().iterated_bias_prior_std;
  o.bias_walk_std = s.params().iterated_bias_walk_std;
  o.iterations = s.params().iterated_iterations;
  return std::make_unique<BiasAugmentedEkfEstimator>(
      K1::kIterated, mitigation::BiasAugmentedEkf(s.motion(), s.params().anchors, Gaussian<4>(), o));
}

/// Registers K1 and its estimators (one line each). "proposed" needs the default QP solver (proxsuite).
inline void register_k1(Registry& r) {
  r.add_scenario<K1>();
  r.add_estimator<K1>("K1", K1::kEkf, make_k1_ekf);  // first, as before issue #4 (callers rely on it)
  if (mitigation::have_default_box_qp()) r.add_estimator<K1>("K1", K1::kProposed, make_k1_proposed);
  r.add_estimator<K1>("K1", K1::kIterated, make_k1_iterated);
  if (mitigation::have_default_box_qp()) r.add_estimator<K1>("K1", K1::kProposedSoft, make_k1_proposed_soft);
}

}  // namespace nlosloc::sim
