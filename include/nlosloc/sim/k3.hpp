#pragma once
/// \file k3.hpp
/// Scenario K3 of reference/scenarios.md: Ke & Wu 2011 (papers/ke-wu2011-qp-ekf.md) Sec. 6.4, short range,
/// node geometry: 4 nodes in a 100 x 100 m area (good: the corners; bad: almost collinear), range noise std
/// 0.02 d_i, NLOS error exponential with mean 0.08 d_i, 1..4 NLOS nodes. Output: P(position error <= 5 m)
/// (Figs. 6-7), for the proposed tracker, the iterated NLOS EKF and the EKF.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "nlosloc/sim/k1.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::sim {

/// Parameters of K3 (Ke & Wu Sec. 6.4 plus the choices listed by K3::choices()).
struct K3Params {
  Mat<4, 2> good = (Mat<4, 2>() << 0, 0, 100, 0, 0, 100, 100, 100).finished();  ///< Sec. 6.4, good geometry
  Mat<4, 2> bad = (Mat<4, 2>() << 0, 0, 38, 39, 80, 81, 100, 100).finished();   ///< Sec. 6.4, bad geometry
  double sigma_rel = 0.02;                 ///< Sec. 6.4: sigma_i = 0.02 d_i
  double nlos_rel = 0.08;                  ///< Sec. 6.4: NLOS error exponential, mean lambda_i = 0.08 d_i
  Vec<2> start{20.0, 20.0};                ///< choice (scenarios.md): start position (m)
  Vec<2> velocity{0.1, 0.15};              ///< Sec. 6.4: (0.1, 0.15) m/s
  double accel_var = 0.01;                 ///< Sec. 6.4: sigma_x^2 = sigma_y^2 = 0.01
  int steps = 200;                         ///< Sec. 6.4: L = 200
  double dt = 0.1;                         ///< Sec. 6.4: 0.1 s
  int discard = 100;                       ///< choice: Sec. 6's "first 100 samples" rule kept
  Vec<4> initial_std{2.0, 2.0, 0.1, 0.1};  ///< choice: initial belief std (m, m, m/s, m/s)
  double threshold = 5.0;                  ///< Sec. 6.4: error threshold (m) of the bench's P(error <= t)
  double gamma = 1.1;                      ///< Sec. 5: eq. (32)
  double iterated_bias_prior_std = 10.0;   ///< choice: iterated NLOS EKF, prior std of each bias (m)
  double iterated_bias_walk_std = 0.5;     ///< choice: iterated NLOS EKF, bias random walk (m/step)
  int iterated_iterations = 3;             ///< choice: iterated NLOS EKF iterations
};

/// K3: cases "good/1NLOS" .. "good/4NLOS", "bad/1NLOS" .. "bad/4NLOS". The NLOS nodes of a case with j NLOS
/// nodes are the last j of the geometry's list (choice, as K1). anchors() and measurements() describe the
/// good geometry; anchors_of(case) gives each case's.
class K3 : public Scenario {
 public:
  static constexpr const char* kProposed = K1::kProposed;
  static constexpr const char* kIterated = K1::kIterated;
  static constexpr const char* kEkf = K1::kEkf;
  static constexpr const char* kProposedSoft = K1::kProposedSoft;

  /// Throws std::invalid_argument naming the first bad field ("K3Params.<field>: expected ...").
  explicit K3(const K3Params& p = K3Params())
      : p_(checked(p)),
        motion_(p.dt, p.accel_var, VelocityNoise::kWhiteAcceleration),
        stack_(ConstantVelocity2::layout(), p.good, 2) {
    // Descriptive stack (good geometry): noise std 0.02 d at the start, NLOS shifted by its mean 0.08 d.
    for (int b = 0; b < 4; ++b) {
      const double d = (p.start - p.good.row(b).transpose()).norm();
      stack_.add_toa(b, {noise::Normal(0.0, p.sigma_rel * d),
                         noise::ShiftedNormal(p.nlos_rel * d, std::hypot(p.sigma_rel * d, p.nlos_rel * d))});
    }
  }

  /// `p` if every field is in range, else std::invalid_argument naming the field. Runs before the members
  /// are built, so the message names the field rather than a model's argument.
  static const K3Params& checked(const K3Params& p) {
    nlosloc::detail::ensure_finite(p.good, "K3Params.good");
    nlosloc::detail::ensure_finite(p.bad, "K3Params.bad");
    nlosloc::detail::ensure_positive(p.sigma_rel, "K3Params.sigma_rel");
    nlosloc::detail::ensure_positive(p.nlos_rel, "K3Params.nlos_rel");
    nlosloc::detail::ensure_positive(p.threshold, "K3Params.threshold");
    check_ke_wu_params(p, "K3Params");
    // the start must not sit on an anchor: the noise std 0.02 d would be 0
    for (const auto* g : {&p.good, &p.bad})
      for (int b = 0; b < 4; ++b)
        NLOSLOC_ENSURE((p.start - g->row(b).transpose()).norm() > 0.0,
                       "K3Params.start: expected a point away from every anchor");
    return p;
  }

  std::string name() const override { return "K3"; }
  std::string description() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    Mat<8, 2> all;  // both geometries: the area is their bounding box
    all << p_.good, p_.bad;
    const double width = all.col(0).maxCoeff() - all.col(0).minCoeff();
    const double height = all.col(1).maxCoeff() - all.col(1).minCoeff();
    return "Ke & Wu 2011 Sec. 6.4: " + f(width) + " x " + f(height) +
           " m, 4 TOA nodes (good: corners; bad: almost collinear), noise std " + f(p_.sigma_rel) +
           " d, NLOS exponential mean " + f(p_.nlos_rel) +
           " d, 1..4 NLOS nodes, L = " + std::to_string(p_.steps) + ", dt = " + f(p_.dt) +
           " s; P(error <= " + f(p_.threshold) + " m)";
  }
  std::vector<std::string> choices() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    std::string init;
    for (int i = 0; i < 4; ++i) init += (i > 0 ? ", " : "") + f(p_.initial_std[i]) + "^2";
    const std::string skip = std::to_string(p_.discard);  // samples left out
    const std::string iterations = p_.iterated_iterations == 1
                                       ? std::string("1 iteration")
                                       : std::to_string(p_.iterated_iterations) + " iterations";
    return {
        "start " + detail::fmt_point(p_.start[0], p_.start[1]) +
            " m (scenarios.md choice), velocity exactly " +
            detail::fmt_point(p_.velocity[0], p_.velocity[1]) +
            " m/s, eq. (16) white acceleration variance " + f(p_.accel_var) +
            " for the truth and the filters",
        "NLOS nodes of a case with j NLOS nodes: the last j nodes of the geometry's list (good: " +
            detail::fmt_point(p_.good(3, 0), p_.good(3, 1)) + " first; bad: " +
            detail::fmt_point(p_.bad(3, 0), p_.bad(3, 1)) + " first); NLOS for the whole run",
        "z_i = d_i + n_i + b_i, n_i ~ N(0, (" + f(p_.sigma_rel) + " d_i)^2), b_i ~ Exp(mean " +
            f(p_.nlos_rel) + " d_i), d_i the true distance, drawn every step",
        "initial belief: truth + N(0, diag(" + init + ")), covariance the same; first " + skip + " of " +
            std::to_string(p_.steps) + " samples left out (Sec. 6's rule); P(error <= " + f(p_.threshold) +
            " m) pooled over runs and samples k >= " + skip,
        "all three filters: R_i = (" + f(p_.sigma_rel) +
            " d^_i)^2 with d^_i the range at the predicted position (the true distance is unknown to them); "
            "EKF = the proposed tracker with mitigation off",
        "iterated NLOS EKF: bias prior N(0, " + f(p_.iterated_bias_prior_std) + "^2), random walk std " +
            f(p_.iterated_bias_walk_std) + " m/step, " + iterations + ", b >= 0",
        "proposed-soft: the proposed tracker with soft threshold lambda = 1 (qp_bias_ekf.hpp, item 4)",
    };
  }
  std::vector<std::string> cases() const override {
    return {"good/1NLOS", "good/2NLOS", "good/3NLOS", "good/4NLOS",
            "bad/1NLOS",  "bad/2NLOS",  "bad/3NLOS",  "bad/4NLOS"};
  }
  int steps() const override { return p_.steps; }
  double dt() const override { return p_.dt; }
  MatX anchors() const override { return p_.good; }
  int discard() const override { return p_.discard; }
  int state_dim() const override { return ConstantVelocity2::kDim; }
  const MeasurementStack& measurements() const override { return stack_; }
  std::string paper_source() const override {
    return "Ke & Wu 2011 Sec. 6.4, Figs. 6-7 (qualitative): proposed P(error <= 5 m) > 85% with good "
           "geometry for 1..4 NLOS nodes, about 3% lower with bad geometry; iterated NLOS EKF good only up "
           "to "
           "2 NLOS nodes; both baselines very poor with bad geometry";
  }

  const K3Params& params() const { return p_; }
  const ConstantVelocity2& motion() const { return motion_; }
  /// True for the bad-geometry cases (indices 4..7).
  static bool bad_geometry(int c) { return c >= 4; }
  /// Number of NLOS nodes of case c (1..4).
  static int nlos_count(int c) { return c % 4 + 1; }
  /// True when node b is NLOS in case c (the last nlos_count(c) nodes).
  static bool is_nlos(int c, int b) { return b >= 4 - nlos_count(c); }
  /// Anchors (4 x 2) of case c.
  MatX anchors_of(int c) const { return bad_geometry(c) ? MatX(p_.bad) : MatX(p_.good); }

 protected:
  void generate(int c, int T, Rng& rng, Draw& d) const override {
    constexpr int B = 4;
    const Mat<4, 2> A = bad_geometry(c) ? p_.bad : p_.good;
    d.states.resize(T, 4);
    d.positions.resize(T, 2);
    d.y.resize(T, B);
    d.sight.resize(T, B);
    d.quality.setConstant(T, B, std::numeric_limits<double>::quiet_NaN());
    Vec<4> x;
    x << p_.start, p_.velocity;
    ke_wu_initial_belief(x, p_.initial_std, rng, d);
    const double sa = std::sqrt(p_.accel_var), dt = p_.dt;
    for (int k = 0; k < T; ++k) {
      if (k > 0) ke_wu_advance(motion_, sa, dt, rng, x);  // Ke & Wu eqs. (16)-(17)
      d.states.row(k) = x.transpose();
      d.positions.row(k) = x.head<2>().transpose();
      for (int b = 0; b < B; ++b) {
        const bool nlos = is_nlos(c, b);
        const double dist = (x.head<2>() - A.row(b).transpose()).norm();
        // Ke & Wu eq. (1), Sec. 6.4: n ~ N(0, (0.02 d)^2), b ~ Exp(mean 0.08 d) by inversion.
        double z = dist + p_.sigma_rel * dist * rng.normal();
        if (nlos) z += -p_.nlos_rel * dist * std::log(rng.uniform());
        d.y(k, b) = z;
        d.sight(k, b) = nlos ? 1 : 0;
      }
    }
  }

 private:
  K3Params p_;
  ConstantVelocity2 motion_;
  MeasurementStack stack_;
};

/// QP-bias EKF with R_i = (0.02 d^_i)^2 and gamma = 1.1, on case c's geometry, soft threshold lambda.
inline std::unique_ptr<Estimator> make_k3_qp_bias_ekf(const char* name, const K3& s, int c, double lambda) {
  mitigation::QpBiasEkfOptions o;
  o.gamma = s.params().gamma;
  o.noise.sigma0 = 0.0;
  o.noise.relative = s.params().sigma_rel;
  o.soft_threshold = lambda;
  return std::make_unique<QpBiasEkfEstimator>(
      name, mitigation::QpBiasEkf(s.motion(), s.anchors_of(c), Gaussian<4>(), o));
}
/// K3 "proposed".
inline std::unique_ptr<Estimator> make_k3_proposed(const K3& s, int c) {
  return make_k3_qp_bias_ekf(K3::kProposed, s, c, 0.0);
}
/// K3 "proposed-soft": soft threshold lambda = 1 (qp_bias_ekf.hpp, item 4).
inline std::unique_ptr<Estimator> make_k3_proposed_soft(const K3& s, int c) {
  return make_k3_qp_bias_ekf(K3::kProposedSoft, s, c, K1::kSoftThreshold);
}
/// K3 "iterated-NLOS-EKF".
inline std::unique_ptr<Estimator> make_k3_iterated(const K3& s, int c) {
  mitigation::BiasAugmentedEkfOptions o;
  o.noise.sigma0 = 0.0;
  o.noise.relative = s.params().sigma_rel;
  o.bias_prior_std = s.params().iterated_bias_prior_std;
  o.bias_walk_std = s.params().iterated_bias_walk_std;
  o.iterations = s.params().iterated_iterations;
  return std::make_unique<BiasAugmentedEkfEstimator>(
      K3::kIterated, mitigation::BiasAugmentedEkf(s.motion(), s.anchors_of(c), Gaussian<4>(), o));
}
/// K3 "EKF": eqs. (20)-(24) with the same R model (the proposed tracker with mitigation off).
inline std::unique_ptr<Estimator> make_k3_ekf(const K3& s, int c) {
  mitigation::QpBiasEkfOptions o;
  o.mitigate = false;
  o.noise.sigma0 = 0.0;
  o.noise.relative = s.params().sigma_rel;
  return std::make_unique<QpBiasEkfEstimator>(
      K3::kEkf, mitigation::QpBiasEkf(s.motion(), s.anchors_of(c), Gaussian<4>(), o));
}

/// Registers K3 and its estimators (one line each).
inline void register_k3(Registry& r) {
  r.add_scenario<K3>();
  if (mitigation::have_default_box_qp()) r.add_estimator<K3>("K3", K3::kProposed, make_k3_proposed);
  r.add_estimator<K3>("K3", K3::kIterated, make_k3_iterated);
  r.add_estimator<K3>("K3", K3::kEkf, make_k3_ekf);
  if (mitigation::have_default_box_qp()) r.add_estimator<K3>("K3", K3::kProposedSoft, make_k3_proposed_soft);
}

/// One line per estimator: P(position error <= threshold) pooled over runs and samples k >= discard
/// (Ke & Wu Sec. 6.4, Figs. 6-7).
inline std::string format_k3_probability(const MonteCarloResult& r, double threshold = 5.0) {
  std::string out;
  char b[256];
  for (const auto& e : r.estimators) {
    const double p = probability_within(pooled_errors(e.errors, r.discard), threshold);
    std::snprintf(b, sizeof b, "  %s %-11s %-20s P(error <= %g m) = %.3f\n", r.scenario.c_str(),
                  r.case_name.c_str(), e.name.c_str(), threshold, p);
    out += b;
  }
  return out;
}

}  // namespace nlosloc::sim
