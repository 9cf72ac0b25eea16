#pragma once
/// \file h1.hpp
/// Scenario H1 of reference/scenarios.md: Huerta et al. 2009 (papers/huerta2009-rbpf-iukf.md) Sec. VI-A,
/// Simulation 1: one tri-sector base station with TOA and AOA (array phase) measurements, a mobile at
/// constant velocity whose sight switches with its transversal speed (eqs. 10, 15, 17); and the estimators
/// the paper compares there: MLE-LOS, EKF-LOS, IUKF and the reordered RBPF with M = 8.
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"
#include "nlosloc/models/noise.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"
#include "nlosloc/sim/estimators.hpp"
#include "nlosloc/sim/scenario.hpp"
#include "nlosloc/situation/forward.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"
#include "nlosloc/snapshot/estimator.hpp"
#include "nlosloc/snapshot/mle_los.hpp"

namespace nlosloc::sim {

/// The belief one prediction earlier whose prediction is `b` exactly: mean F^-1 m, covariance
/// F^-1 (P - Q) F^-T. Filters that always predict before updating (Rbpf) start from it, so their first
/// update sees the draw's initial belief at t_0 (scenario.hpp convention). Falls back to `b` itself when
/// P - Q is not positive definite. `b` must be a belief (Gaussian::validate, named "belief").
template <class Motion>
Gaussian<Motion::kDim> backdate(const Motion& motion, const Gaussian<Motion::kDim>& b) {
  constexpr int N = Motion::kDim;
  b.validate("belief");  // a NaN mean or an indefinite covariance came back as a start
  const Mat<N, N> Fi = motion.F().inverse();
  Mat<N, N> P = Fi * (b.cov - motion.Q()) * Fi.transpose();
  P = 0.5 * (P + P.transpose()).eval();
  if (!is_spd(P)) return b;
  return Gaussian<N>(Fi * b.mean, P);
}

/// Runs an rbpf::Rbpf (classical or reordered) as an Estimator: reset() restarts it from the draw's initial
/// belief, every step runs Rbpf::step(y, o) (so the first update follows one prediction of the initial
/// belief: the backdated start of backdate() made every UKF update of H2's first step fail, under
/// investigation); the sight estimate is the per-anchor argmax of the situation probabilities.
template <class Motion>
class RbpfEstimator final : public Estimator {
 public:
  static constexpr int kDim = Motion::kDim;
  /// `filter`: the RBPF (held by pointer: it owns a thread pool and is not movable).
  RbpfEstimator(std::string name, std::unique_ptr<rbpf::Rbpf<Motion>> filter)
      : name_(std::move(name)), f_(std::move(filter)) {
    NLOSLOC_ENSURE(f_ != nullptr, "filter: expected an Rbpf, got null");
  }
  std::string name() const override { return name_; }
  void reset(const Draw& d, Rng& /*rng: deterministic filter*/) override {
    detail::ensure_shape(d.initial_mean, kDim, 1, "draw.initial_mean");
    detail::ensure_shape(d.initial_cov, kDim, kDim, "draw.initial_cov");
    const Gaussian<kDim> b(d.initial_mean, d.initial_cov);
    // Not backdated (see backdate()): Rbpf predicts once before its first update, from the belief at t_0.
    f_->reset(b, 0.0);
  }
  void step(int /*k*/, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o,
            Eigen::Ref<VecX> position_out) override {
    f_->step(y, o);
    const StateLayout& L = f_->measurements().layout();
    position_out = f_->estimate().segment(L.position, L.space_dim);
  }
  bool estimates_sight() const override { return true; }
  void sight_estimate(Eigen::Ref<VecXi> out) const override { out = f_->sight_estimate(); }
  const rbpf::Rbpf<Motion>& filter() const { return *f_; }

 private:
  std::string name_;
  std::unique_ptr<rbpf::Rbpf<Motion>> f_;
};

/// Runs an Iukf (Huerta Table VI with the forward filter of eqs. 35-38) as an Estimator: reset() restarts
/// the forward filter and sets the draw's initial belief backdated one step; every step is step_quality(y,
/// o).
template <class Motion>
class IukfEstimator final : public Estimator {
 public:
  static constexpr int kDim = Motion::kDim;
  IukfEstimator(std::string name, Iukf<Motion> filter) : name_(std::move(name)), f_(std::move(filter)) {}
  std::string name() const override { return name_; }
  void reset(const Draw& d, Rng& /*rng: deterministic filter*/) override {
    detail::ensure_shape(d.initial_mean, kDim, 1, "draw.initial_mean");
    detail::ensure_shape(d.initial_cov, kDim, kDim, "draw.initial_cov");
    f_.set_belief(backdate(f_.motion(), Gaussian<kDim>(d.initial_mean, d.initial_cov)), -f_.motion().dt());
    f_.forward().reset();
  }
  void step(int /*k*/, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o,
            Eigen::Ref<VecX> position_out) override {
    f_.step_quality(y, o);
    const StateLayout& L = f_.measurements().layout();
    position_out = f_.mean().segment(L.position, L.space_dim);
  }
  bool estimates_sight() const override { return true; }
  void sight_estimate(Eigen::Ref<VecXi> out) const override { out = f_.sight_estimate(); }

 private:
  std::string name_;
  Iukf<Motion> f_;
};

/// Runs the joint rbpf::ParticleFilter as an Estimator. The filter is rebuilt at every reset() with a seed
/// drawn from the estimator's own stream for the run (so runs use independent particle draws and the
/// result does not depend on the worker), and starts from the draw's initial belief backdated one step.
template <class Motion>
class PfEstimator final : public Estimator {
 public:
  static constexpr int kDim = Motion::kDim;
  PfEstimator(std::string name, Motion motion, MeasurementStack meas, situation::SightProcess sight,
              situation::QualityModel quality, rbpf::PfOptions options)
      : name_(std::move(name)),
        motion_(std::move(motion)),
        meas_(std::move(meas)),
        sight_(std::move(sight)),
        quality_(std::move(quality)),
        opt_(options) {}
  std::string name() const override { return name_; }
  void reset(const Draw& d, Rng& rng) override {
    detail::ensure_shape(d.initial_mean, kDim, 1, "draw.initial_mean");
    detail::ensure_shape(d.initial_cov, kDim, kDim, "draw.initial_cov");
    rbpf::PfOptions o = opt_;
    o.seed = rng();
    const Gaussian<kDim> b = backdate(motion_, Gaussian<kDim>(d.initial_mean, d.initial_cov));
    f_.reset();  // release the previous run's buffers first
    f_ =
        std::make_unique<rbpf::ParticleFilter<Motion>>(motion_, meas_, sight_, quality_, b, o, -motion_.dt());
  }
  void step(int /*k*/, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o,
            Eigen::Ref<VecX> position_out) override {
    f_->step(y, o);
    const StateLayout& L = meas_.layout();
    position_out = f_->estimate().segment(L.position, L.space_dim);
  }
  bool estimates_sight() const override { return true; }
  void sight_estimate(Eigen::Ref<VecXi> out) const override { out = f_->sight_estimate(); }

 private:
  std::string name_;
  Motion motion_;
  MeasurementStack meas_;
  situation::SightProcess sight_;
  situation::QualityModel quality_;
  rbpf::PfOptions opt_;
  std::unique_ptr<rbpf::ParticleFilter<Motion>> f_;
};

/// Parameters of H1; defaults are Huerta Tables VII-VIII plus the choices listed by H1::choices().
struct H1Params {
  double dt = 0.01;                       ///< Table VII: Delta t = 0.01 s
  int steps = 20000;                      ///< Table VII: 200 s
  double speed = 10.0;                    ///< Table VII: MS speed 10 m/s (constant)
  Vec<2> start{-1000.0, 400.0};           ///< choice: start (m), heading +x
  Vec<2> heading{1.0, 0.0};               ///< choice: direction of motion (unit vector)
  double mean_los = 30.0;                 ///< Table VII: E{L_LOS} (m)
  double mean_nlos = 5.0;                 ///< Table VII: E{L_NLOS} (m)
  double sigma_v2 = 1.0;                  ///< Table VII: sigma_v^2, filter design only ((m/s)^2 per s)
  double toa_los_var = 10.0;              ///< Table VIII: TOA LOS Normal, variance 10 m^2
  double toa_nlos_var = 2000.0;           ///< Table VIII: TOA NLOS Rayleigh, variance 2000 m^2
  double aoa_los_var = 1e-5;              ///< Table VIII: AOA LOS Normal, variance 1e-5 rad^2
  double aoa_nlos_var = 1e-3;             ///< Table VIII: AOA NLOS Normal, variance 1e-3 rad^2
  Vec<3> sector_deg{90.0, 210.0, 330.0};  ///< choice: broadside of the three 120-degree sectors (deg)
  double quality_los_a = 4.0, quality_los_b = 1.5;    ///< choice: o | LOS ~ Beta(4, 1.5)
  double quality_nlos_a = 1.5, quality_nlos_b = 4.0;  ///< choice: o | NLOS ~ Beta(1.5, 4)
  Vec<4> initial_std{10.0, 10.0, 1.0, 1.0};           ///< choice: initial belief std (m, m, m/s, m/s)
  int discard = 0;                                    ///< choice: no transient left out
  int rbpf_particles = 8;                             ///< Sec. VI-A: reordered RBPF with M = 8
};

/// H1: one BS at the origin with three sector arrays; rows: TOA, then the phase of each sector (only the
/// serving sector's row is present at a step, the other two are NaN). One case, "default".
class H1 : public Scenario {
 public:
  static constexpr const char* kMle = "MLE-LOS";
  static constexpr const char* kEkf = "EKF-LOS";
  static constexpr const char* kIukf = "IUKF";
  static constexpr const char* kRbpf = "rRBPF-8";
  static constexpr const char* kRbpfAug = "rRBPF-8-aug";  ///< the same with Table III's noise sigma set

  /// Throws std::invalid_argument naming the first bad field ("H1Params.<field>: expected ...").
  explicit H1(const H1Params& p = H1Params())
      : p_(checked(p)),
        motion_(p.dt, p.sigma_v2, VelocityNoise::kRandomWalk),
        stack_(make_stack(p)),
        sight_(situation::SightModel::speed_dependent(p.mean_los, p.mean_nlos, p.dt,
                                                      situation::SpeedModel::kMultiple),
               1),
        quality_los_(p.quality_los_a, p.quality_los_b),
        quality_nlos_(p.quality_nlos_a, p.quality_nlos_b) {}

  /// `p` if every field is in range, else std::invalid_argument naming the field. Runs before the members
  /// are built, so the message names the H1Params field rather than a model's argument.
  static const H1Params& checked(const H1Params& p) {
    NLOSLOC_ENSURE(p.steps > p.discard && p.discard >= 0,
                   "H1Params: expected 0 <= discard < steps, got discard " + std::to_string(p.discard) +
                       ", steps " + std::to_string(p.steps));
    detail::ensure_positive(p.dt, "H1Params.dt");
    detail::ensure_positive(p.speed, "H1Params.speed");
    detail::ensure_finite(p.start, "H1Params.start");
    NLOSLOC_ENSURE(std::abs(p.heading.norm() - 1.0) < 1e-9, "H1Params.heading: expected a unit vector");
    detail::ensure_positive(p.mean_los, "H1Params.mean_los");
    detail::ensure_positive(p.mean_nlos, "H1Params.mean_nlos");
    detail::ensure_nonnegative(p.sigma_v2, "H1Params.sigma_v2");
    detail::ensure_positive(p.toa_los_var, "H1Params.toa_los_var");
    detail::ensure_positive(p.toa_nlos_var, "H1Params.toa_nlos_var");
    detail::ensure_positive(p.aoa_los_var, "H1Params.aoa_los_var");
    detail::ensure_positive(p.aoa_nlos_var, "H1Params.aoa_nlos_var");
    detail::ensure_finite(p.sector_deg, "H1Params.sector_deg");
    detail::ensure_positive(p.quality_los_a, "H1Params.quality_los_a");
    detail::ensure_positive(p.quality_los_b, "H1Params.quality_los_b");
    detail::ensure_positive(p.quality_nlos_a, "H1Params.quality_nlos_a");
    detail::ensure_positive(p.quality_nlos_b, "H1Params.quality_nlos_b");
    // the initial belief's std: > 0 so its covariance diag(initial_std^2) is SPD
    for (int i = 0; i < 4; ++i)
      detail::ensure_positive(p.initial_std[i], ("H1Params.initial_std[" + std::to_string(i) + "]").c_str());
    NLOSLOC_ENSURE(p.rbpf_particles >= 1,
                   "H1Params.rbpf_particles: expected >= 1, got " + std::to_string(p.rbpf_particles));
    return p;
  }

  std::string name() const override { return "H1"; }
  std::string description() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    return "Huerta et al. 2009 Sec. VI-A: one tri-sector BS, TOA + AOA phase, mobile at " + f(p_.speed) +
           " m/s, speed-dependent LOS/NLOS (E{L_LOS} = " + f(p_.mean_los) +
           " m, E{L_NLOS} = " + f(p_.mean_nlos) + " m), dt = " + f(p_.dt) + " s, " + f(p_.steps * p_.dt) +
           " s";
  }
  std::vector<std::string> choices() const override {
    const auto f = [](double v) { return detail::fmt_num(v); };
    // serving-sector changes along the truth's path (generate()'s)
    int changes = 0;
    for (int k = 0, prev = -1; k < p_.steps; ++k) {
      const Vec<2> pos = truth_position(k);
      const int j = serving_sector(std::atan2(pos[1], pos[0]));
      if (prev >= 0 && j != prev) ++changes;
      prev = j;
    }
    const std::string path = changes == 0   ? std::string("never changes sector")
                             : changes == 1 ? std::string("changes sector once")
                             : changes == 2 ? std::string("changes sector twice")
                                            : "changes sector " + std::to_string(changes) + " times";
    const Vec<2>& h = p_.heading;  // a unit vector (checked): +x, -x, +y, -y or (h_x, h_y)
    const std::string heading = h[1] == 0.0   ? std::string(h[0] > 0.0 ? "+x" : "-x")
                                : h[0] == 0.0 ? std::string(h[1] > 0.0 ? "+y" : "-y")
                                              : detail::fmt_point(h[0], h[1]);
    const double p_n = sight_.model(0).initial()(1);  // eq. (18): the chain's prior of s_0
    const noise::Rayleigh toa_nlos = noise::Rayleigh::from_variance(p_.toa_nlos_var);
    // initial belief variances as s^2 (a unit std printed as 1)
    std::string init;
    for (int i = 0; i < 4; ++i) {
      const double s = p_.initial_std[i];
      init += (i > 0 ? ", " : "") + (s == 1.0 ? std::string("1") : f(s) + "^2");
    }
    const std::string discarded = detail::fmt_discarded(p_.discard);
    return {
        "BS at the origin with sectors of 120 deg whose broadsides point at " + f(p_.sector_deg[0]) + ", " +
            f(p_.sector_deg[1]) + " and " + f(p_.sector_deg[2]) +
            " deg; the serving sector is the one whose span contains the mobile's bearing (the path " + path +
            ", Fig. 10)",
        "AOA = electric phase psi = pi sin(theta - theta_sector) of a half-wavelength ULA of the serving "
        "sector (Table I psi); one phase row per sector, NaN when the sector does not serve; noise added to "
        "the phase",
        "mobile starts at " + detail::fmt_point(p_.start[0], p_.start[1]) + " m heading " + heading +
            " at exactly " + f(p_.speed) +
            " m/s (no process noise in the truth, Table VII note); sigma_v^2 = " + f(p_.sigma_v2) +
            " only in the filters' random-walk model (eq. 6)",
        "sight: one two-state chain, eq. (17) with the transversal speed of eq. (10), s_0 drawn from eq. "
        "(18) (p_N = " +
            f(p_.mean_nlos) + "/" + f(p_.mean_los + p_.mean_nlos) + " = " + detail::fmt_num(p_n, 3) + ")",
        "noise (Table VIII): 'variance' is the distribution's variance: TOA LOS N(0, " + f(p_.toa_los_var) +
            "), NLOS Rayleigh with variance " + f(p_.toa_nlos_var) + " (scale " +
            detail::fmt_num(toa_nlos.scale(), 3) + " m, mean " + detail::fmt_num(toa_nlos.mean(), 3) +
            " m, no Gaussian term added); phase LOS N(0, " + f(p_.aoa_los_var) + "), NLOS N(0, " +
            f(p_.aoa_nlos_var) + ")",
        "quality statistic o ~ " + detail::fmt_beta(p_.quality_los_a, p_.quality_los_b) + " in LOS, " +
            detail::fmt_beta(p_.quality_nlos_a, p_.quality_nlos_b) + " in NLOS, independent per step",
        "initial belief: mean = true state + N(0, diag(" + init +
            ")) drawn once per run and shared by all estimators; covariance diag(" + init +
            "); first update with y_0, " + discarded,
        "MLE-LOS: Gauss-Newton ML of the current TOA + phase assuming LOS (exactly determined: the polar "
        "inversion of range and bearing); EKF-LOS: EKF with the LOS noise on every row",
    };
  }
  std::vector<std::string> cases() const override { return {"default"}; }
  int steps() const override { return p_.steps; }
  double dt() const override { return p_.dt; }
  MatX anchors() const override { return MatX::Zero(1, 2); }
  int discard() const override { return p_.discard; }
  int state_dim() const override { return ConstantVelocity2::kDim; }
  const MeasurementStack& measurements() const override { return stack_; }
  std::string paper_source() const override {
    return "Huerta et al. 2009 Fig. 13 (CDF only, no table; the paper's p_N = 0.14 from eq. 18)";
  }

  const H1Params& params() const { return p_; }
  /// Filters' motion model: Huerta eqs. (6)-(7), random walk with sigma_v^2.
  const ConstantVelocity2& motion() const { return motion_; }
  /// The sight process of the single anchor (eq. 17).
  const situation::SightProcess& sight_process() const { return sight_; }
  /// Quality likelihoods per condition (choice Beta(4, 1.5) / Beta(1.5, 4)).
  std::vector<noise::Distribution> quality() const { return {quality_los_, quality_nlos_}; }
  /// Index (0..2) of the sector serving a mobile at bearing theta (rad).
  int serving_sector(double theta) const {
    NLOSLOC_ENSURE(std::isfinite(theta),
                   "theta: expected a finite bearing (rad), got " + std::to_string(theta));
    int best = 0;
    double dmin = 1e300;
    for (int j = 0; j < 3; ++j) {
      const double d = std::abs(wrap_angle(theta - p_.sector_deg[j] * kPi / 180.0));
      if (d < dmin) {
        dmin = d;
        best = j;
      }
    }
    return best;
  }

 protected:
  /// The truth's position at step k: constant velocity from the start (Table VII, no process noise).
  Vec<2> truth_position(int k) const { return p_.start + (k * p_.dt) * (p_.speed * p_.heading); }

  void generate(int /*c*/, int T, Rng& rng, Draw& d) const override {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    d.states.resize(T, 4);
    d.positions.resize(T, 2);
    d.y.setConstant(T, 4, nan);
    d.sight.resize(T, 1);
    d.quality.resize(T, 1);
    const Vec<2> v = p_.speed * p_.heading;
    Vec<4> x0;
    x0 << p_.start, v;
    d.initial_mean.resize(4);
    for (int i = 0; i < 4; ++i) d.initial_mean[i] = x0[i] + p_.initial_std[i] * rng.normal();
    d.initial_cov = p_.initial_std.array().square().matrix().asDiagonal();

    VecXi s = sight_.sample_initial(rng);
    VecX w(1);
    const MatX q = MatX::Zero(1, 2);
    for (int k = 0; k < T; ++k) {
      const Vec<2> pos = truth_position(k);
      if (k > 0) {
        situation::transversal_speeds(pos, v, q, w);  // eq. (10)
        s = sight_.sample_next(s, k, w, rng);         // eq. (17)
      }
      d.states.row(k) << pos.transpose(), v.transpose();
      d.positions.row(k) = pos.transpose();
      d.sight(k, 0) = s[0];
      const int z = s[0];
      // Table I: TOA ||p - q|| and phase psi(angle); Table VIII noise of the current condition.
      const double theta = std::atan2(pos[1], pos[0]);
      d.y(k, 0) = pos.norm() + stack_.noise(0, z).sample(rng);
      const int j = serving_sector(theta);
      const double psi = kPi * std::sin(theta - p_.sector_deg[j] * kPi / 180.0);
      d.y(k, 1 + j) = psi + stack_.noise(1 + j, z).sample(rng);
      d.quality(k, 0) = (z == 0 ? quality_los_ : quality_nlos_).sample(rng);
    }
  }

 private:
  static MeasurementStack make_stack(const H1Params& p) {
    MeasurementStack st(ConstantVelocity2::layout(), MatX::Zero(1, 2), 2);
    st.add_toa(
        0, {noise::Normal(0.0, std::sqrt(p.toa_los_var)), noise::Rayleigh::from_variance(p.toa_nlos_var)});
    for (int j = 0; j < 3; ++j)
      st.add_aoa_phase(
          0, p.sector_deg[j] * kPi / 180.0,
          {noise::Normal(0.0, std::sqrt(p.aoa_los_var)), noise::Normal(0.0, std::sqrt(p.aoa_nlos_var))});
    return st;
  }

  H1Params p_;
  ConstantVelocity2 motion_;
  MeasurementStack stack_;
  situation::SightProcess sight_;
  noise::Beta quality_los_, quality_nlos_;
};

/// H1 "MLE-LOS": per-epoch LOS ML fix (Huerta Sec. VI-A), snapshot/mle_los.hpp.
inline std::unique_ptr<Estimator> make_h1_mle(const H1& s, int /*case_index*/) {
  return make_snapshot_estimator(H1::kMle, snapshot::MleLos(s.measurements()));
}

/// H1 "EKF-LOS": EKF with every measurement assumed LOS (Huerta Sec. VI-A, [37]).
inline std::unique_ptr<Estimator> make_h1_ekf(const H1& s, int /*case_index*/) {
  return make_filter_estimator(H1::kEkf, Ekf<ConstantVelocity2>(s.motion(), s.measurements(), Gaussian<4>()),
                               SightPolicy::kAssumeLos);
}

/// H1 "IUKF": Huerta Table VI with the per-anchor forward filter (eqs. 35-38) on the eq. (17) chain.
inline std::unique_ptr<Estimator> make_h1_iukf(const H1& s, int /*case_index*/) {
  return std::make_unique<IukfEstimator<ConstantVelocity2>>(
      H1::kIukf, Iukf<ConstantVelocity2>(
                     s.motion(), s.measurements(), Gaussian<4>(),
                     situation::ForwardFilter(s.sight_process(), situation::QualityModel(s.quality()))));
}

/// H1 reordered RBPF (Huerta Table V) with M = 8, sight chain eq. (17), quality likelihoods, and the UKF
/// noise form `form`.
inline std::unique_ptr<Estimator> make_h1_rbpf_form(const H1& s, const char* name, NoiseForm form) {
  rbpf::RbpfOptions o;
  o.variant = rbpf::RbpfVariant::kReordered;
  o.num_particles = s.params().rbpf_particles;
  o.noise_form = form;
  return std::make_unique<RbpfEstimator<ConstantVelocity2>>(
      name, std::make_unique<rbpf::Rbpf<ConstantVelocity2>>(s.motion(), s.measurements(), s.sight_process(),
                                                            situation::QualityModel(s.quality()),
                                                            Gaussian<4>(), o));
}
/// H1 "rRBPF-8": the additive-noise UKF (the library's default).
inline std::unique_ptr<Estimator> make_h1_rbpf(const H1& s, int /*case_index*/) {
  return make_h1_rbpf_form(s, H1::kRbpf, NoiseForm::kAdditive);
}
/// H1 "rRBPF-8-aug": the UKF of Table III as written (noise sigma set, UkfAugmented).
inline std::unique_ptr<Estimator> make_h1_rbpf_aug(const H1& s, int /*case_index*/) {
  return make_h1_rbpf_form(s, H1::kRbpfAug, NoiseForm::kAugmented);
}

/// Registers H1 and its estimators (one line each).
inline void register_h1(Registry& r) {
  r.add_scenario<H1>();
  r.add_estimator<H1>("H1", H1::kMle, make_h1_mle);
  r.add_estimator<H1>("H1", H1::kEkf, make_h1_ekf);
  r.add_estimator<H1>("H1", H1::kIukf, make_h1_iukf);
  r.add_estimator<H1>("H1", H1::kRbpf, make_h1_rbpf);
  r.add_estimator<H1>("H1", H1::kRbpfAug, make_h1_rbpf_aug);
}

}  // namespace nlosloc::sim
