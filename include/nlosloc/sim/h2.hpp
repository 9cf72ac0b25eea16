#pragma once
/// \file h2.hpp
/// Scenario H2 of reference/scenarios.md: Huerta et al. 2009 (papers/huerta2009-rbpf-iukf.md) Sec. VI-B,
/// Simulation 2: six anchors on a hexagon of 3 km side, RTOA with an unsynchronised mobile (clock bias and
/// drift in the state, eq. 5), random-walk motion, LOS/NLOS with E{L_LOS} = E{L_NLOS} = 10 m; and the
/// estimators the paper compares there: EKF-LOS, CHEN, CONG, URR, IUKF, cRBPF-128, rRBPF-16, rRBPF-128, PF;
/// plus rRBPF-128-aug, rRBPF-128 with Table III's noise sigma set (RbpfOptions::noise_form).
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"
#include "nlosloc/models/noise.hpp"
#include "nlosloc/sim/estimators.hpp"
#include "nlosloc/sim/h1.hpp"
#include "nlosloc/sim/scenario.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/snapshot/estimator.hpp"

namespace nlosloc::sim {

/// Parameters of H2; defaults are Huerta Tables IX-X plus the choices listed by H2::choices().
struct H2Params {
  double side = 3000.0;           ///< Sec. VI-B: hexagon of 3 km side (= circumradius)
  double dt = 0.01;               ///< Table IX: Delta t = 0.01 s
  int steps = 6000;               ///< Table IX: 60 s
  double sigma_v2 = 1.0;          ///< Table IX: sigma_v^2 = 1 (m/s)^2, velocity random walk (eq. 6)
  double sigma_tau2 = 1e-2;       ///< Table IX: sigma_tau^2 = 1e-2 (lm/s)^2 (drift random walk, eq. 6)
  double tau0_var = 10.0;         ///< Table IX: E{tau_0^2} = 10 lm^2
  double tau_dot0_var = 10.0;     ///< Table IX: E{tau_dot_0^2} = 10 (lm/s)^2
  double mean_los = 10.0;         ///< Table IX: E{L_LOS} (m)
  double mean_nlos = 10.0;        ///< Table IX: E{L_NLOS} (m)
  double rtoa_los_var = 10.0;     ///< Table X: RTOA LOS Normal, variance 10
  double rtoa_nlos_var = 5000.0;  ///< Table X: RTOA NLOS Rayleigh, variance 5000
  double position0_std = 1.0;     ///< choice: std of the start about the centre (m), truth and prior
  double velocity0_std = 1.0;     ///< choice: std of the initial velocity (m/s), truth and prior
  double quality_los_a = 4.0, quality_los_b = 1.5;    ///< choice: o | LOS ~ Beta(4, 1.5)
  double quality_nlos_a = 1.5, quality_nlos_b = 4.0;  ///< choice: o | NLOS ~ Beta(1.5, 4)
  int discard = 0;                                    ///< choice: no transient left out
  double urr_speed = 5.0;      ///< choice: transversal speed (m/s) giving URR's fixed transition probability
  int pf_particles = 1000000;  ///< Sec. VI-B: PF with 1e6 particles
};

/// H2: six RTOA anchors, state [p (2), tau, v (2), tau_dot] (ConstantVelocityClock2). One case, "default".
class H2 : public Scenario {
 public:
  static constexpr const char* kEkf = "EKF-LOS";
  static constexpr const char* kChen = "CHEN";
  static constexpr const char* kCong = "CONG";
  static constexpr const char* kUrr = "URR";
  static constexpr const char* kIukf = "IUKF";
  static constexpr const char* kCrbpf128 = "cRBPF-128";
  static constexpr const char* kRrbpf16 = "rRBPF-16";
  static constexpr const char* kRrbpf128 = "rRBPF-128";
  static constexpr const char* kRrbpf128Aug = "rRBPF-128-aug";  ///< with Table III's noise sigma set
  static constexpr const char* kPf = "PF";

  /// Throws std::invalid_argument naming the first bad field ("H2Params.<field>: expected ...").
  explicit H2(const H2Params& p = H2Params())
      : p_(checked(p)),
        motion_(p.dt, p.sigma_v2, p.sigma_tau2),
        anchors_(hexagon(p.side)),
        stack_(make_stack(p, anchors_)),
        sight_(situation::SightModel::speed_dependent(p.mean_los, p.mean_nlos, p.dt,
                                                      situation::SpeedModel::kMultiple),
               6),
        quality_los_(p.quality_los_a, p.quality_los_b),
        quality_nlos_(p.quality_nlos_a, p.quality_nlos_b) {}

  /// `p` if every field is in range, else std::invalid_argument naming the field. Runs before the members
  /// are built, so the message names the H2Params field rather than a model's argument.
  static const H2Params& checked(const H2Params& p) {
    NLOSLOC_ENSURE(p.steps > p.discard && p.discard >= 0,
                   "H2Params: expected 0 <= discard < steps, got discard " + std::to_string(p.discard) +
                       ", steps " + std::to_string(p.steps));
    detail::ensure_positive(p.side, "H2Params.side");
    detail::ensure_positive(p.dt, "H2Params.dt");
    detail::ensure_nonnegative(p.sigma_v2, "H2Params.sigma_v2");
    detail::ensure_nonnegative(p.sigma_tau2, "H2Params.sigma_tau2");
    // variances of the prior x_0 (drawn with their square roots): > 0 so the prior covariance is SPD
    detail::ensure_positive(p.tau0_var, "H2Params.tau0_var");
    detail::ensure_positive(p.tau_dot0_var, "H2Params.tau_dot0_var");
    detail::ensure_positive(p.mean_los, "H2Params.mean_los");
    detail::ensure_positive(p.mean_nlos, "H2Params.mean_nlos");
    detail::ensure_positive(p.rtoa_los_var, "H2Params.rtoa_los_var");
    detail::ensure_positive(p.rtoa_nlos_var, "H2Params.rtoa_nlos_var");
    detail::ensure_positive(p.position0_std, "H2Params.position0_std");
    detail::ensure_positive(p.velocity0_std, "H2Params.velocity0_std");
    detail::ensure_positive(p.quality_los_a, "H2Params.quality_los_a");
    detail::ensure_positive(p.quality_los_b, "H2Params.quality_los_b");
    detail::ensure_positive(p.quality_nlos_a, "H2Params.quality_nlos_a");
    detail::ensure_positive(p.quality_nlos_b, "H2Params.quality_nlos_b");
    detail::ensure_positive(p.urr_speed, "H2Params.urr_speed");
    NLOSLOC_ENSURE(p.pf_particles >= 1,
                   "H2Params.pf_particles: expected >= 1, got " + std::to_string(p.pf_particles));
    return p;
  }

  std::string name() const override { return "H2"; }
  std::string description() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    const std::string means = p_.mean_los == p_.mean_nlos ? "E{L_LOS} = E{L_NLOS} = " + f(p_.mean_los) + " m"
                                                          : "E{L_LOS} = " + f(p_.mean_los) +
                                                                " m, E{L_NLOS} = " + f(p_.mean_nlos) + " m";
    return "Huerta et al. 2009 Sec. VI-B: 6 RTOA anchors on a " + f(p_.side / 1000.0) +
           " km hexagon, unsynchronised mobile (clock bias and drift), velocity random walk sigma_v^2 = " +
           f(p_.sigma_v2) + ", " + means + ", dt = " + f(p_.dt) + " s, " + f(p_.steps * p_.dt) + " s";
  }
  std::vector<std::string> choices() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    const Vec<6> var = prior_variances();
    std::string prior;
    for (int i = 0; i < 6; ++i) prior += (i > 0 ? ", " : "") + f(var[i]);
    const noise::Rayleigh rtoa_nlos = noise::Rayleigh::from_variance(p_.rtoa_nlos_var);
    const double p_n = sight_.model(0).initial()(1);  // eq. (18): the chains' prior of s_0
    // URR's per-step switch probabilities (eq. 15): one number when E{L_LOS} = E{L_NLOS}
    const double p_ln = urr_switch_probability(0), p_nl = urr_switch_probability(1);
    const std::string switches = p_ln == p_nl ? detail::fmt_num(p_ln, 2)
                                              : "LOS -> NLOS " + detail::fmt_num(p_ln, 2) + ", NLOS -> LOS " +
                                                    detail::fmt_num(p_nl, 2);
    const std::string discarded = detail::fmt_discarded(p_.discard);
    return {
        "anchors at the hexagon vertices (" + f(p_.side) + " cos(60 k deg), " + f(p_.side) +
            " sin(60 k deg)), k = 0..5",
        "truth drawn from the filters' model (eqs. 4-7, ConstantVelocityClock2): x_0 ~ N(0, diag(" + prior +
            ")) (start at the centre with std " + f(p_.position0_std) + " m, velocity std " +
            f(p_.velocity0_std) +
            " m/s, Table IX clock priors); the initial belief of every estimator is that prior (mean 0)",
        "RTOA y_b = ||p - q_b|| + tau + n (Table I); noise (Table X) LOS N(0, " + f(p_.rtoa_los_var) +
            "), NLOS Rayleigh with variance " + f(p_.rtoa_nlos_var) + " (scale " +
            detail::fmt_num(rtoa_nlos.scale(), 4) + ", mean " + detail::fmt_num(rtoa_nlos.mean(), 4) +
            "; no Gaussian term added)",
        "sight: one two-state chain per anchor, eq. (17) with the transversal speed of eq. (10), s_0 from "
        "eq. (18) (p_N = " +
            detail::fmt_num(p_n, 3) + "), anchors independent (eq. 9)",
        "quality statistic o ~ " + detail::fmt_beta(p_.quality_los_a, p_.quality_los_b) + " in LOS, " +
            detail::fmt_beta(p_.quality_nlos_a, p_.quality_nlos_b) + " in NLOS, per anchor and step",
        discarded + "; first update with y_0",
        "EKF-LOS: EKF with the LOS noise on every row (eq. 6-7 model)",
        "CHEN: all anchor sets of >= 4 anchors (over-determined for p, tau), normalised residual / set size, "
        "50% with the largest residual rejected, residual-weighted mean; per-set ML by Gauss-Newton (not "
        "simulated annealing)",
        "CONG: residual test (chi-square 99%, discarded residuals > -3 sigma) for the largest consistent set "
        "of >= 4 anchors; if none, the 4 rows with the smallest residuals under a split normal fitted to the "
        "NLOS noise (noise::AsymmetricNormal::fit of 20000 draws)",
        "URR: hypotheses = LOS sets of >= 3 anchors, TDOA ML (RTOA with a free clock), uniform NLOS density "
        "over W = " +
            detail::fmt_num(urr_nlos_span(), 4) +
            " m (99% quantile of the NLOS noise), per-anchor switch probability of eq. (15) at a transversal "
            "speed of " +
            f(p_.urr_speed) + " m/s (" + switches + " per step), P(NLOS) = " + detail::fmt_num(p_n, 3) +
            " at t = 0; Viterbi decision without delay",
    };
  }
  std::vector<std::string> cases() const override { return {"default"}; }
  int steps() const override { return p_.steps; }
  double dt() const override { return p_.dt; }
  MatX anchors() const override { return anchors_; }
  int discard() const override { return p_.discard; }
  int state_dim() const override { return ConstantVelocityClock2::kDim; }
  const MeasurementStack& measurements() const override { return stack_; }
  std::string paper_source() const override {
    return "Huerta et al. 2009 Figs. 14-15 (CDFs only, no table): PF <= rRBPF-128 < cRBPF-128 ~ rRBPF-16 < "
           "IUKF, "
           "CHEN/CONG/URR good about 50% of the time, EKF-LOS worst";
  }

  const H2Params& params() const { return p_; }
  /// Filters' motion model: Huerta eqs. (5)-(7), unsynchronised mobile.
  const ConstantVelocityClock2& motion() const { return motion_; }
  /// The sight process (one eq. 17 chain per anchor).
  const situation::SightProcess& sight_process() const { return sight_; }
  /// Quality likelihoods per condition (choice Beta(4, 1.5) / Beta(1.5, 4)).
  std::vector<noise::Distribution> quality() const { return {quality_los_, quality_nlos_}; }
  /// Diagonal of the prior covariance of x_0 = [p, tau, v, tau_dot] (choices + Table IX).
  Vec<6> prior_variances() const {
    Vec<6> v;
    const double p2 = p_.position0_std * p_.position0_std, v2 = p_.velocity0_std * p_.velocity0_std;
    v << p2, p2, p_.tau0_var, v2, v2, p_.tau_dot0_var;
    return v;
  }
  /// URR's per-step probability of leaving `condition` (0 LOS, 1 NLOS) at w = urr_speed: eq. (15)
  /// p_LN = w dt / (w dt + E{L_LOS}) for condition 0, p_NL = w dt / (w dt + E{L_NLOS}) for condition 1.
  double urr_switch_probability(int condition) const {
    NLOSLOC_ENSURE(
        condition == 0 || condition == 1,
        "condition: expected 0 (LOS -> NLOS) or 1 (NLOS -> LOS), got " + std::to_string(condition));
    const double a = p_.urr_speed * p_.dt;
    return a / (a + (condition == 0 ? p_.mean_los : p_.mean_nlos));
  }
  /// URR's uniform NLOS span W: the 99% quantile of the NLOS noise (Rayleigh, Table X).
  double urr_nlos_span() const { return stack_.noise(0, 1).quantile(0.99); }

 protected:
  void generate(int /*c*/, int T, Rng& rng, Draw& d) const override {
    constexpr int B = 6;
    d.states.resize(T, 6);
    d.positions.resize(T, 2);
    d.y.resize(T, B);
    d.sight.resize(T, B);
    d.quality.resize(T, B);
    const Vec<6> var = prior_variances();
    d.initial_mean = VecX::Zero(6);
    d.initial_cov = var.asDiagonal();
    Vec<6> x;
    for (int i = 0; i < 6; ++i) x[i] = std::sqrt(var[i]) * rng.normal();  // x_0 ~ prior
    const Vec<6> qstd = motion_.Q().diagonal().cwiseSqrt();               // eq. (6), diagonal
    VecXi s = sight_.sample_initial(rng);
    VecX w(B);
    for (int k = 0; k < T; ++k) {
      if (k > 0) {
        x = motion_.F() * x;  // eq. (4), (7)
        for (int i = 0; i < 6; ++i)
          if (qstd[i] > 0.0) x[i] += qstd[i] * rng.normal();
        situation::transversal_speeds(x.head<2>(), x.segment<2>(3), anchors_, w);  // eq. (10)
        s = sight_.sample_next(s, k, w, rng);                                      // eqs. (9), (17)
      }
      d.states.row(k) = x.transpose();
      d.positions.row(k) = x.head<2>().transpose();
      for (int b = 0; b < B; ++b) {
        const int z = s[b];
        d.sight(k, b) = z;
        // Table I RTOA: ||p - q_b|| + tau, Table X noise of the current condition.
        d.y(k, b) =
            (x.head<2>() - anchors_.row(b).transpose()).norm() + x[2] + stack_.noise(b, z).sample(rng);
        d.quality(k, b) = (z == 0 ? quality_los_ : quality_nlos_).sample(rng);
      }
    }
  }

 private:
  static MatX hexagon(double r) {
    MatX a(6, 2);
    for (int k = 0; k < 6; ++k) {
      a(k, 0) = r * std::cos(k * kPi / 3.0);
      a(k, 1) = r * std::sin(k * kPi / 3.0);
    }
    return a;
  }
  static MeasurementStack make_stack(const H2Params& p, const MatX& anchors) {
    MeasurementStack st(ConstantVelocityClock2::layout(), anchors, 2);
    for (int b = 0; b < 6; ++b)
      st.add_rtoa(b, {noise::Normal(0.0, std::sqrt(p.rtoa_los_var)),
                      noise::Rayleigh::from_variance(p.rtoa_nlos_var)});
    return st;
  }

  H2Params p_;
  ConstantVelocityClock2 motion_;
  MatX anchors_;
  MeasurementStack stack_;
  situation::SightProcess sight_;
  noise::Beta quality_los_, quality_nlos_;
};

/// H2 "EKF-LOS": EKF with every anchor assumed LOS (Huerta Sec. VI-B).
inline std::unique_ptr<Estimator> make_h2_ekf(const H2& s, int /*case_index*/) {
  return make_filter_estimator(H2::kEkf,
                               Ekf<ConstantVelocityClock2>(s.motion(), s.measurements(), Gaussian<6>()),
                               SightPolicy::kAssumeLos);
}
/// H2 "CHEN": Chen 1999 residual weighting, 50% of the combinations rejected (snapshot/chen.hpp).
inline std::unique_ptr<Estimator> make_h2_chen(const H2& s, int /*case_index*/) {
  return make_snapshot_estimator(H2::kChen, snapshot::Chen(s.measurements()));
}
/// H2 "CONG": Cong & Zhuang 2005 (snapshot/cong.hpp).
inline std::unique_ptr<Estimator> make_h2_cong(const H2& s, int /*case_index*/) {
  return make_snapshot_estimator(H2::kCong, snapshot::Cong(s.measurements()));
}
/// H2 "URR": Riba & Urruela ML detection with trellis search on TDOA (snapshot/urruela.hpp).
inline std::unique_ptr<Estimator> make_h2_urr(const H2& s, int /*case_index*/) {
  snapshot::UrruelaOptions o;
  o.p_nlos = s.params().mean_nlos / (s.params().mean_los + s.params().mean_nlos);  // eq. (18)
  o.p_ln = s.urr_switch_probability(0);                                            // eq. (15), E{L_LOS}
  o.p_nl = s.urr_switch_probability(1);                                            // eq. (15), E{L_NLOS}
  o.nlos_span = s.urr_nlos_span();
  return make_snapshot_estimator(H2::kUrr, snapshot::Urruela(s.measurements(), o));
}

/// H2 "IUKF": Huerta Table VI with the per-anchor forward filter (eqs. 35-38).
inline std::unique_ptr<Estimator> make_h2_iukf(const H2& s, int /*case_index*/) {
  return std::make_unique<IukfEstimator<ConstantVelocityClock2>>(
      H2::kIukf, Iukf<ConstantVelocityClock2>(
                     s.motion(), s.measurements(), Gaussian<6>(),
                     situation::ForwardFilter(s.sight_process(), situation::QualityModel(s.quality()))));
}

/// H2 RBPF of Huerta Sec. VI-B: `variant` classical (Table IV) or reordered (Table V) with M particles.
inline std::unique_ptr<Estimator> make_h2_rbpf(const H2& s, const char* name, rbpf::RbpfVariant variant,
                                               int M, NoiseForm form = NoiseForm::kAdditive) {
  rbpf::RbpfOptions o;
  o.variant = variant;
  o.num_particles = M;
  o.noise_form = form;
  return std::make_unique<RbpfEstimator<ConstantVelocityClock2>>(
      name, std::make_unique<rbpf::Rbpf<ConstantVelocityClock2>>(
                s.motion(), s.measurements(), s.sight_process(), situation::QualityModel(s.quality()),
                Gaussian<6>(), o));
}
/// H2 "cRBPF-128": classical RBPF, M = 2 propagated particles, 2 x 2^6 = 128 UKF runs per step.
inline std::unique_ptr<Estimator> make_h2_crbpf128(const H2& s, int /*case_index*/) {
  return make_h2_rbpf(s, H2::kCrbpf128, rbpf::RbpfVariant::kClassical, 2);
}
/// H2 "rRBPF-16": reordered RBPF, M = 16 UKF runs and propagated particles.
inline std::unique_ptr<Estimator> make_h2_rrbpf16(const H2& s, int /*case_index*/) {
  return make_h2_rbpf(s, H2::kRrbpf16, rbpf::RbpfVariant::kReordered, 16);
}
/// H2 "rRBPF-128": reordered RBPF, M = 128.
inline std::unique_ptr<Estimator> make_h2_rrbpf128(const H2& s, int /*case_index*/) {
  return make_h2_rbpf(s, H2::kRrbpf128, rbpf::RbpfVariant::kReordered, 128);
}
/// H2 "rRBPF-128-aug": rRBPF-128 with the UKF of Table III as written (noise sigma set, UkfAugmented):
/// the Rayleigh NLOS noise enters through its quantile map instead of its mean and variance.
inline std::unique_ptr<Estimator> make_h2_rrbpf128_aug(const H2& s, int /*case_index*/) {
  return make_h2_rbpf(s, H2::kRrbpf128Aug, rbpf::RbpfVariant::kReordered, 128, NoiseForm::kAugmented);
}

/// H2 "PF": joint particle filter over (x, s) with 1e6 particles and the paper's merge-and-select
/// (Sec. VI-B: "the resampling is performed as for the RBPF"), one thread per filter (the runner spreads
/// runs).
inline std::unique_ptr<Estimator> make_h2_pf(const H2& s, int /*case_index*/) {
  rbpf::PfOptions o;
  o.num_particles = s.params().pf_particles;
  o.resampling = rbpf::PfResampling::kMergeSelect;
  return std::make_unique<PfEstimator<ConstantVelocityClock2>>(
      H2::kPf, s.motion(), s.measurements(), s.sight_process(), situation::QualityModel(s.quality()), o);
}

/// Registers H2 and its estimators (one line each).
inline void register_h2(Registry& r) {
  r.add_scenario<H2>();
  r.add_estimator<H2>("H2", H2::kEkf, make_h2_ekf);
  r.add_estimator<H2>("H2", H2::kChen, make_h2_chen);
  r.add_estimator<H2>("H2", H2::kCong, make_h2_cong);
  r.add_estimator<H2>("H2", H2::kUrr, make_h2_urr);
  r.add_estimator<H2>("H2", H2::kIukf, make_h2_iukf);
  r.add_estimator<H2>("H2", H2::kCrbpf128, make_h2_crbpf128);
  r.add_estimator<H2>("H2", H2::kRrbpf16, make_h2_rrbpf16);
  r.add_estimator<H2>("H2", H2::kRrbpf128, make_h2_rrbpf128);
  r.add_estimator<H2>("H2", H2::kRrbpf128Aug, make_h2_rrbpf128_aug);
  r.add_estimator<H2>("H2", H2::kPf, make_h2_pf);
}

}  // namespace nlosloc::sim
