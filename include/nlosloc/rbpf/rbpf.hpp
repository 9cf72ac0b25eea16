#pragma once
/// \file rbpf.hpp
/// Rao-Blackwellized particle filter of Huerta et al. 2009 (Sec. V-A, V-B): a deterministic particle filter
/// over the situation vectors s_1:t (eqs. 20-25) with a bank of UKFs for the kinetic state given each
/// particle's situation history (eq. 26, Table III), merge and select (eqs. 29-31), in the classical order
/// (Table IV: expand, UKF every child, weight, merge/select) or the reordered one (Table V: expand, weight by
/// prior and quality statistic, merge/select, then UKF only the M survivors).
///
/// Choices the paper leaves open (documented here and in the report):
///  - the UKF is by default the additive-noise form with each row's exact noise mean and variance under the
///    particle's situation (Ukf of filters/ukf.hpp): the sigma points of a parent serve all its children.
///    RbpfOptions::noise_form = kAugmented runs Table III as written, the noise sigma set inside the points
///    (UkfAugmented), at one full sigma-point evaluation per child. Either way eq. (25)'s likelihood is the
///    Gaussian predictive N(y; y_hat, S);
///  - the first step has no previous situation: its transition prior is the chains' prior propagated once,
///    p(s_1) = pi T (the particle set starts as one particle of weight one);
///  - in the reordered order the children are compared (eq. 29) by their predicted means F x_{t-1};
///  - eq. (31)'s position variance is the trace of the position block of the last mixture covariance;
///  - estimate (eq. 28), mixture covariance and situation probabilities: over all weighted children in the
///    classical order (as eq. 28 sums over i and k), over the M updated particles in the reordered order.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/rbpf/merge.hpp"
#include "nlosloc/rbpf/offspring.hpp"
#include "nlosloc/rbpf/phase_profile.hpp"
#include "nlosloc/rbpf/snapshot_check.hpp"
#include "nlosloc/rbpf/thread_pool.hpp"
#include "nlosloc/rbpf/ukf_kernel.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace nlosloc::rbpf {

/// Order of the RBPF iteration.
enum class RbpfVariant {
  kClassical = 0,  ///< Table IV: M x N_z^B UKF runs per step
  kReordered = 1   ///< Table V: M UKF runs per step
};

/// Settings of Rbpf.
struct RbpfOptions {
  RbpfVariant variant = RbpfVariant::kReordered;
  int num_particles = 16;              ///< M, particles propagated to the next step (>= 1)
  std::uint64_t max_offspring = 4096;  ///< children per particle; N_z^B above it -> bounded enumeration
  bool merge = true;                   ///< apply the merge of eqs. (29)-(30) before selecting
  double merge_threshold = -1.0;       ///< d_min; negative: eq. (31) from the position variance
  /// pool threads (created once); phases with < 64 parents or updates run on one. No result depends on
  /// it, bit for bit (the bank's chunks and their partial sums do not depend on the threads).
  int threads = 1;
  SigmaScheme scheme = SigmaScheme::scaled();   ///< sigma points of the per-particle UKF
  NoiseForm noise_form = NoiseForm::kAdditive;  ///< UKF noise: moments (default) or sigma set (Table III)
};

/// What an Rbpf carries from one step to the next (Rbpf::save / Rbpf::restore): a checkpoint of a long
/// track, and what pickling stores from Python. P particles (1 <= P <= M), B anchors, N_z conditions, n
/// state entries.
struct RbpfSnapshot {
  Eigen::MatrixXi situations;    ///< P x B condition indices, 0 .. N_z - 1 (0 = LOS)
  MatX means;                    ///< P x n kinetic means (eq. 26)
  std::vector<MatX> covs;        ///< P covariances n x n (eq. 26)
  VecX log_weights;              ///< P normalised log weights (their log-sum-exp is 0)
  MatX situation_probabilities;  ///< B x N_z, rows summing to 1
  VecX estimate;                 ///< eq. (28)
  MatX covariance;               ///< eq. (27), moment matched
  double time = 0.0;             ///< (s)
  long step = 0;                 ///< steps since the reset; 0: the next step draws from the initial sight
};

/// What one RBPF step reports.
struct RbpfStepInfo {
  double log_likelihood = 0.0;   ///< log of the weight normaliser: approx. log p(y_t, o_t | y_1:t-1, o_1:t-1)
  int offspring = 0;             ///< children generated (eq. 23)
  int ukf_runs = 0;              ///< UKF updates run
  int merged = 0;                ///< children absorbed by the merge (eq. 30)
  int failures = 0;              ///< UKF updates rejected (covariance not positive definite); weight 0
  double merge_threshold = 0.0;  ///< d_min used
  CholeskyStatus status = CholeskyStatus::kOk;  ///< worst factorisation outcome among the UKF runs
};

/// RBPF over a linear motion model and a measurement stack.
template <class Motion, class Meas = MeasurementStack>
class Rbpf {
 public:
  static constexpr int N = Motion::kDim;
  using State = Vec<N>;
  using Cov = Mat<N, N>;
  /// The leading components of a predicted mean (two, or N when N < 2): the neighbour sweep buckets and
  /// pre-tests on them (prepare_sweep).
  static constexpr int kLead = N < 2 ? N : 2;
  using Lead = Vec<kLead>;

  Rbpf(const Motion& motion, const Meas& meas, situation::SightProcess sight, situation::QualityModel quality,
       const Gaussian<N>& initial, const RbpfOptions& options = {}, double t0 = 0.0)
      : motion_(motion),
        meas_(meas),
        sight_(std::move(sight)),
        quality_(std::move(quality)),
        opt_(options),
        threads_(options.threads),
        barrier_(std::make_unique<SpinBarrier>()),
        shared_cut_(std::make_unique<SharedCut[]>(static_cast<std::size_t>(std::max(options.threads, 1)))) {
    ::nlosloc::detail::check_layout<N>(meas);
    meas.check_ready();
    if (options.noise_form == NoiseForm::kAdditive) meas.check_finite_moments("Rbpf (additive UKF bank)");
    NLOSLOC_ENSURE(options.num_particles >= 1,
                   "options.num_particles: expected M >= 1, got " + std::to_string(options.num_particles));
    NLOSLOC_ENSURE(options.max_offspring >= 1, "options.max_offspring: expected >= 1");
    NLOSLOC_ENSURE(options.variant == RbpfVariant::kClassical || options.variant == RbpfVariant::kReordered,
                   "options.variant: unknown RbpfVariant");
    NLOSLOC_ENSURE(options.noise_form == NoiseForm::kAdditive || options.noise_form == NoiseForm::kAugmented,
                   "options.noise_form: unknown NoiseForm");
    NLOSLOC_ENSURE(std::isfinite(options.merge_threshold),
                   "options.merge_threshold: expected a finite value");
    NLOSLOC_ENSURE(sight_.num_anchors() == meas.num_anchors(),
                   "sight: expected " + std::to_string(meas.num_anchors()) +
                       " anchors (as the measurements), got " + std::to_string(sight_.num_anchors()));
    NLOSLOC_ENSURE(sight_.num_conditions() == meas.num_conditions(),
                   "sight: expected " + std::to_string(meas.num_conditions()) + " conditions per anchor");
    NLOSLOC_ENSURE(quality_.num_conditions() == meas.num_conditions(),
                   "quality: expected " + std::to_string(meas.num_conditions()) + " conditions");
    NLOSLOC_ENSURE(!sight_.speed_dependent() || meas.layout().velocity >= 0,
                   "sight: a speed-dependent chain needs a velocity in the state layout");
    options.scheme.validate(UkfKernel<Motion, Meas>::sigma_dim(meas, options.noise_form));
    B_ = meas.num_anchors();
    nz_ = meas.num_conditions();
    const std::uint64_t total = situation_count(nz_, B_);
    NLOSLOC_ENSURE(total != 0, "sight: N_z^B does not fit in 62 bits; reduce the anchors per filter");
    per_parent_ = static_cast<int>(std::min<std::uint64_t>(total, options.max_offspring));
    full_enum_ = static_cast<std::uint64_t>(per_parent_) == total;
    pow_nz_.assign(static_cast<std::size_t>(B_), 1);
    for (int b = 1; b < B_; ++b)
      pow_nz_[static_cast<std::size_t>(b)] =
          pow_nz_[static_cast<std::size_t>(b) - 1] * static_cast<std::uint64_t>(nz_);
    const int M = options.num_particles;
    const auto cap = static_cast<std::size_t>(M) * static_cast<std::size_t>(per_parent_);
    NLOSLOC_ENSURE(cap <= (std::size_t{1} << 26),
                   "options: M x children per particle too large (> 2^26); lower max_offspring");
    off_parent_.resize(cap);
    off_key_.resize(cap);
    off_logw_.resize(cap);
    if (options.variant == RbpfVariant::kClassical) {
      off_mean_.resize(cap);
      off_cov_.resize(cap);
    }
    mean_.resize(static_cast<std::size_t>(M));
    cov_.resize(static_cast<std::size_t>(M));
    key_.resize(static_cast<std::size_t>(M));
    logw_.resize(static_cast<std::size_t>(M));
    nmean_ = mean_;
    ncov_ = cov_;
    nkey_ = key_;
    nlogw_ = logw_;
    xpred_.resize(static_cast<std::size_t>(M));
    xlead_.resize(static_cast<std::size_t>(M));
    adj_.assign(static_cast<std::size_t>(M) * static_cast<std::size_t>(M), 0);
    key_count_ = total;
    sel_.reserve(cap);
    if (options.variant == RbpfVariant::kClassical) mws_.reserve(cap);
    grid_.reserve(static_cast<std::size_t>(M));
    slead_.reserve(static_cast<std::size_t>(M));
    sweep_split_.assign(static_cast<std::size_t>(kSweepChunks) + 1, 0);
    // Each thread allocates its own kernel and scratch, from its own glibc arena (Threads frees them the
    // same way). Allocated in turn by the caller, one thread's buffers could share cache lines with the
    // next thread's; H2 rRBPF-128, interleaved 1/2-thread pairs: speed-up 1.44-1.47 before, 1.46-1.50 after.
    threads_.kernels.resize(static_cast<std::size_t>(threads_.pool->size()));
    threads_.work.resize(static_cast<std::size_t>(threads_.pool->size()));
    threads_.pool->parallel_for(threads_.pool->size(), [&](int, int, int th) {
      const auto t = static_cast<std::size_t>(th);
      threads_.kernels[t] =
          std::make_unique<UkfKernel<Motion, Meas>>(meas_, options.scheme, options.noise_form);
      auto w = std::make_unique<ThreadWork>();
      w->T.resize(nz_, nz_);
      w->speeds.setZero(B_);
      w->s.setZero(B_);
      w->crec.reserve(kCandidateSlack * static_cast<std::size_t>(M));
      w->half.reserve(static_cast<std::size_t>(M));
      w->sel_w.reserve(kCandidateSlack * static_cast<std::size_t>(M));
      w->sel_tmp.reserve(kCandidateSlack * static_cast<std::size_t>(M));
      w->sel_ties.reserve(kCandidateSlack * static_cast<std::size_t>(M));
      w->psorted.reserve(static_cast<std::size_t>(M));
      w->mprob.setZero(B_, nz_);
      w->opt.assign(static_cast<std::size_t>(B_) * static_cast<std::size_t>(nz_), 0);
      w->ktmp.assign(3 * static_cast<std::size_t>(M), 0.0);
      w->near.assign(static_cast<std::size_t>(M), 0);
      w->apar.assign(static_cast<std::size_t>(M), MatX::Zero(B_, nz_));
      w->best.assign(static_cast<std::size_t>(M), 0.0);
      w->known.assign(3 * static_cast<std::size_t>(M), 0.0);
      if (th > 0 && options.variant == RbpfVariant::kReordered) {  // speculate runs on the other threads only
        w->spec.resize(static_cast<std::size_t>(kMaxSpeculated));
        w->spec_rec.resize(static_cast<std::size_t>(kMaxSpeculated));
      }
      if (options.variant == RbpfVariant::kReordered) {
        w->sub.reserve(cap);
        w->sub_parent.reserve(cap);
        w->sub_key.reserve(cap);
        w->sub_logw.reserve(cap);
        w->mws.reserve(cap);
      }
      if (static_cast<std::uint64_t>(per_parent_) < total)
        w->bfw.reserve(B_, nz_, static_cast<std::uint64_t>(per_parent_));
      threads_.work[t] = std::move(w);
    });
    thread_fail_.assign(static_cast<std::size_t>(threads_.pool->size()), 0);
    chunk_.assign(static_cast<std::size_t>(kMaxChunks) + 1, 0);
    back_cut_.assign(static_cast<std::size_t>(kSideChunks), 0);
    // bank_split's marks: at most M kept children (reordered) or every child (classical)
    split_first_.assign(options.variant == RbpfVariant::kReordered ? static_cast<std::size_t>(M) : cap, 0);
    csum_.resize(static_cast<std::size_t>(kMaxChunks));
    for (auto& c : csum_) c.mprob.setZero(B_, nz_);
    thread_status_.assign(static_cast<std::size_t>(threads_.pool->size()), CholeskyStatus::kOk);
    Lq_.resize(B_, nz_);
    crec_.reserve(static_cast<std::size_t>(M) * static_cast<std::size_t>(threads_.pool->size()));
    sel_w_.reserve(static_cast<std::size_t>(M) * static_cast<std::size_t>(threads_.pool->size()));
    sel_tmp_.reserve(static_cast<std::size_t>(M) * static_cast<std::size_t>(threads_.pool->size()));
    sel_ties_.reserve(static_cast<std::size_t>(M) * static_cast<std::size_t>(threads_.pool->size()));
    sel_order_.reserve(static_cast<std::size_t>(M));
    pstart_.assign(static_cast<std::size_t>(M) + 1, 0);
    prob_.resize(B_, nz_);
    y_.resize(meas.rows());
    reset(initial, t0);
  }

  /// Restarts from one particle N(initial) with no situation history, at time t0.
  void reset(const Gaussian<N>& initial, double t0 = 0.0) {
    initial.validate("initial");
    NLOSLOC_ENSURE(std::isfinite(t0), "t0: expected a finite time (s)");
    count_ = 1;
    mean_[0] = initial.mean;
    cov_[0] = initial.cov;
    key_[0] = 0;
    logw_[0] = 0.0;
    logw_shift_ = 0.0;
    first_ = true;
    t_ = t0;
    k_ = 0;
    est_ = initial.mean;
    est_cov_ = initial.cov;
    prob_.setZero();
    for (int b = 0; b < B_; ++b) prob_.row(b) = sight_.model(b).initial().transpose();
    pos_var_ = position_variance(initial.cov);
    xpred_ready_ = false;
  }

  /// Everything the next step depends on (the particles, their weights, the summaries, time and step
  /// index): restore() of it into a filter built with the same models and options makes that filter step
  /// on exactly as this one, bit for bit, on any number of threads.
  RbpfSnapshot save() const {
    RbpfSnapshot s;
    s.situations.resize(count_, B_);
    s.means.resize(count_, N);
    s.covs.resize(static_cast<std::size_t>(count_));
    s.log_weights.resize(count_);
    VecXi sit(B_);
    for (int i = 0; i < count_; ++i) {
      const auto u = static_cast<std::size_t>(i);
      decode_situation(key_[u], nz_, sit);
      s.situations.row(i) = sit.transpose();
      s.means.row(i) = mean_[u].transpose();
      s.covs[u] = cov_[u];
      s.log_weights[i] = normalised_logw(i);
    }
    s.situation_probabilities = prob_;
    s.estimate = est_;
    s.covariance = est_cov_;
    s.time = t_;
    s.step = k_;
    return s;
  }

  /// Sets the filter to a snapshot (save() of a filter with the same models and options, or one built by
  /// hand). Checked first, std::invalid_argument naming the field (the filter is then unchanged): 1 <= P
  /// <= options().num_particles particles; situations P x B in 0 .. N_z - 1; finite means; symmetric
  /// positive definite covariances; log weights finite or -inf, with a log-sum-exp within 1e-9 of 0;
  /// probabilities B x N_z in [0, 1] with rows summing to 1, both within 1e-9; a finite estimate and a
  /// positive definite covariance; a finite time; step >= 0.
  void restore(const RbpfSnapshot& s) {
    const Eigen::Index P = s.situations.rows();
    NLOSLOC_ENSURE(P >= 1 && P <= opt_.num_particles, "snapshot.situations: expected 1 to " +
                                                          std::to_string(opt_.num_particles) +
                                                          " particles (rows), got " + std::to_string(P));
    ::nlosloc::detail::ensure_shape(s.situations, P, B_, "snapshot.situations");
    NLOSLOC_ENSURE(s.situations.minCoeff() >= 0 && s.situations.maxCoeff() < nz_,
                   "snapshot.situations: expected condition indices 0 to " + std::to_string(nz_ - 1));
    ::nlosloc::detail::ensure_shape(s.means, P, N, "snapshot.means");
    ::nlosloc::detail::ensure_finite(s.means, "snapshot.means");
    NLOSLOC_ENSURE(static_cast<Eigen::Index>(s.covs.size()) == P,
                   "snapshot.covs: expected " + std::to_string(P) + " covariances, got " +
                       std::to_string(s.covs.size()));
    for (std::size_t i = 0; i < s.covs.size(); ++i) {
      const std::string name = "snapshot.covs[" + std::to_string(i) + "]";
      ::nlosloc::detail::ensure_shape(s.covs[i], N, N, name.c_str());
      NLOSLOC_ENSURE(is_spd(s.covs[i]), name + ": expected a symmetric positive definite matrix");
    }
    ::nlosloc::detail::ensure_shape(s.log_weights, P, 1, "snapshot.log_weights");
    detail::check_snapshot_log_weights(s.log_weights);
    ::nlosloc::detail::ensure_shape(s.situation_probabilities, B_, nz_, "snapshot.situation_probabilities");
    const auto& pr = s.situation_probabilities.array();
    // 1e-9 of slack: the filter's own sums of weights may exceed 1 by rounding (1 + 2e-15 seen on H2)
    NLOSLOC_ENSURE(
        pr.allFinite() && (pr >= -1e-9).all() && (pr <= 1.0 + 1e-9).all() &&
            ((s.situation_probabilities.rowwise().sum().array() - 1.0).abs() <= 1e-9).all(),
        "snapshot.situation_probabilities: expected probabilities in [0, 1] with rows summing to 1");
    ::nlosloc::detail::ensure_shape(s.estimate, N, 1, "snapshot.estimate");
    ::nlosloc::detail::ensure_finite(s.estimate, "snapshot.estimate");
    ::nlosloc::detail::ensure_shape(s.covariance, N, N, "snapshot.covariance");
    NLOSLOC_ENSURE(is_spd(s.covariance),
                   "snapshot.covariance: expected a symmetric positive definite matrix");
    detail::check_snapshot_clock(s.time, s.step);
    count_ = static_cast<int>(P);
    for (int i = 0; i < count_; ++i) {
      const auto u = static_cast<std::size_t>(i);
      key_[u] = encode_situation(s.situations.row(i), nz_);
      mean_[u] = s.means.row(i).transpose();
      cov_[u] = s.covs[u];
      logw_[u] = s.log_weights[i];
    }
    logw_shift_ = 0.0;
    prob_ = s.situation_probabilities;
    est_ = s.estimate;
    est_cov_ = s.covariance;
    t_ = s.time;
    k_ = s.step;
    first_ = s.step == 0;
    pos_var_ = position_variance(est_cov_);
    xpred_ready_ = false;
    parent_split_ = 0;
  }

  /// One iteration with measurements y (size rows; NaN = missing) and quality statistics o (size B;
  /// NaN = missing). Throws NumericalError (state unchanged) when every UKF update fails.
  RbpfStepInfo step(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) {
    phase_profile::begin_step();
    situation::check_step_inputs(meas_, quality_, y, o, Lq_);
    y_ = y;
    RbpfStepInfo info;
    info.merge_threshold = opt_.merge_threshold >= 0.0
                               ? opt_.merge_threshold
                               : default_merge_threshold(pos_var_, opt_.num_particles);  // eq. (31)
    const long k = k_ + 1;
    const double t = t_ + motion_.dt();
    if (opt_.variant == RbpfVariant::kReordered)
      step_reordered(k, t, info);
    else
      step_classical(k, t, info);
    k_ = k;
    t_ = t;
    first_ = false;
    pos_var_ = position_variance(est_cov_);
    phase_profile::mark(0, phase_profile::kStepEnd);
    return info;
  }

  // ---- results ------------------------------------------------------------------------------------
  /// Number of particles carried to the next step (<= M).
  int num_particles() const { return count_; }
  /// Normalised log weight of particle i.
  double log_weight(int i) const { return normalised_logw(check(i)); }
  /// Normalised weights (size num_particles()).
  VecX weights() const {
    VecX w(count_);
    for (int i = 0; i < count_; ++i) w(i) = std::exp(normalised_logw(i));
    return w;
  }
  /// Kinetic mean / covariance of particle i (eq. 26).
  const State& particle_mean(int i) const { return mean_[static_cast<std::size_t>(check(i))]; }
  const Cov& particle_cov(int i) const { return cov_[static_cast<std::size_t>(check(i))]; }
  /// Current situation vector of particle i (B entries).
  VecXi particle_situation(int i) const {
    VecXi s(B_);
    decode_situation(key_[static_cast<std::size_t>(check(i))], nz_, s);
    return s;
  }
  /// State estimate, eq. (28).
  const State& estimate() const { return est_; }
  /// Covariance of the Gaussian mixture of eq. (27) (moment matched).
  const Cov& covariance() const { return est_cov_; }
  Gaussian<N> belief() const { return {est_, est_cov_}; }
  /// P(s_b = z | y_1:t, o_1:t), B x N_z.
  const MatX& situation_probabilities() const { return prob_; }
  /// Most probable condition of every anchor (argmax of situation_probabilities()).
  VecXi sight_estimate() const {
    VecXi s(B_);
    for (int b = 0; b < B_; ++b) prob_.row(b).maxCoeff(&s(b));
    return s;
  }
  double time() const { return t_; }
  long step_index() const { return k_; }
  int num_anchors() const { return B_; }
  int num_conditions() const { return nz_; }
  /// Children per particle: N_z^B or the bound max_offspring.
  int children_per_particle() const { return per_parent_; }
  const RbpfOptions& options() const { return opt_; }
  const Motion& motion() const { return motion_; }
  const Meas& measurements() const { return meas_; }
  /// The sight chains and quality likelihoods it was built with (what a copy of its set-up needs).
  const situation::SightProcess& sight_process() const { return sight_; }
  const situation::QualityModel& quality() const { return quality_; }
  /// Throws the std::invalid_argument step(y, o) would throw for these inputs, and changes nothing: checks
  /// a batch before its first step (the Python run() does).
  void check_inputs(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) const {
    situation::check_step_inputs(meas_, quality_, y, o);
  }

 private:
  int check(int i) const {
    NLOSLOC_ENSURE(i >= 0 && i < count_,
                   "i: expected a particle index in [0, " + std::to_string(count_) + ")");
    return i;
  }
  double position_variance(const Cov& P) const {
    const auto& L = meas_.layout();
    return P.diagonal().segment(L.position, L.space_dim).sum();
  }

  /// Threads for a parallel phase over n items: the whole pool from kMinParallel items on, else one. Below
  /// that, the hand-offs cost more than the second core saves (H2 model: 2 threads are slower at M = 16,
  /// even at M = 24-48 and faster from M = 64; bench/tools note in the commit).
  static constexpr int kMinParallel = 64;
  int active_threads(int n) const { return n >= kMinParallel ? threads_.pool->size() : 1; }

  /// A child for the UKF bank: its parent, prior log weight, situation key and child index (p x children
  /// per parent + j).
  struct BankChild {
    int parent;
    double prior;
    std::uint64_t key;
    int idx;
  };

  /// A kept child's UKF update made ahead of the bank (speculate), by child index.
  struct Speculated {
    int idx = -1;
    bool ok = false;
    CholeskyStatus status = CholeskyStatus::kOk;
    double logw = 0.0;
    State x;
    Cov P;
  };
  /// At most this many per thread and step: the selection it overlaps lasts a few updates.
  static constexpr int kMaxSpeculated = 12;

  /// Per-thread scratch of the expansion and the UKF bank.
  struct ThreadWork {
    MatX T;
    VecX speeds;
    VecXi s;
    std::vector<ChildRecord> crec;       // this thread's candidates (keep_candidate; finish_candidates)
    std::vector<double> half;            // min-heap of the H heaviest offered weights (enumerate_share)
    std::vector<double> sel_w, sel_tmp;  // keep_heaviest scratch of crec
    std::vector<ChildRecord> sel_ties;
    std::vector<int> psorted;  // this thread's share of the parents, by decreasing best child
    std::vector<double> ktmp;  // scratch copy of known
    std::vector<int> opt;      // B x N_z: each anchor's conditions by decreasing factor (offer_pruned)
    std::vector<char> near;    // near[p] = 1 when this thread's sweep found a neighbour of parent p
    // merge_share: this thread's children of parents with a neighbour, their keys and log weights
    std::vector<int> sub, sub_parent;
    std::vector<std::uint64_t> sub_key;
    std::vector<double> sub_logw;
    MergeWorkspace mws;
    int merged = 0;          // children absorbed by this thread's merge
    BestFirstWorkspace bfw;  // bounded enumeration (reserved at construction when it is used)
    MatX mprob;              // chunk_moments: situation weights of the chunk being summed
    // The factors, best child weight and three known child weights of the thread's own parents, parent p
    // in slot p - first (parent_bounds): written and read by this thread only. In arrays shared by the
    // threads and indexed by parent, the 2-thread factors took 28.0-29.8 us of work per step against
    // 26.9 on one thread, 28.1 so (nlosloc-rbpf-phases --pin 0,1); rRBPF-128 on H2, 4 alternating
    // lockstep rounds of rbpf_speedup.py: 2-thread step 76.2-77.0 -> 75.6-76.2 us (2026-12-04).
    int first = 0;
    std::vector<MatX> apar;  // factors A (B x N_z)
    std::vector<double> best, known;
    // speculate: the children updated ahead of the bank (by decreasing index) and the candidates it takes
    std::vector<Speculated> spec;
    int nspec = 0;
    std::vector<ChildRecord> spec_rec;
  };

  /// Weighted sums of one bank chunk's updated particles relative to its largest log weight mmax
  /// (chunk_moments): m0 = sum of w, m1 = sum of w (x - c), m2 = sum of w (P + (x - c)(x - c)^T),
  /// mprob = sum of w per anchor and condition. A line of its own: the threads write chunks side by side.
  struct alignas(64) ChunkMoments {
    double mmax = 0.0, m0 = 0.0;
    State m1;
    Cov m2;
    MatX mprob;
  };

  /// The pool and each pool thread's UKF kernel and scratch (threads x entries). Each thread allocates
  /// (Rbpf constructor) and frees (here) its own entries: freed by the caller, glibc kept the worker's
  /// blocks in the caller's cache (tcache) and served the next filter's thread-0 scratch from them, next
  /// to its thread-1 scratch; 2-thread rRBPF-128 on H2 then took 71-92 us per step depending on the
  /// filters made before it, 69-79 us with this (12 filters made in turn; commit b60f6d7). The pool is
  /// owned through a pointer (workers keep its address), so Rbpf stays movable.
  struct Threads {
    std::unique_ptr<ThreadPool> pool;
    std::vector<std::unique_ptr<UkfKernel<Motion, Meas>>> kernels;
    std::vector<std::unique_ptr<ThreadWork>> work;

    explicit Threads(int n) : pool(std::make_unique<ThreadPool>(n)) {}
    ~Threads() { release(); }
    Threads(Threads&&) = default;
    Threads& operator=(Threads&& other) noexcept {
      if (this != &other) {
        release();
        pool = std::move(other.pool);
        kernels = std::move(other.kernels);
        work = std::move(other.work);
      }
      return *this;
    }
    /// Frees each thread's entries on that thread (a moved-from or one-thread set: on this one).
    void release() noexcept {
      if (!pool || pool->size() < 2 || kernels.size() != static_cast<std::size_t>(pool->size())) return;
      try {
        pool->parallel_for(pool->size(), [&](int, int, int th) {
          kernels[static_cast<std::size_t>(th)].reset();
          work[static_cast<std::size_t>(th)].reset();
        });
      } catch (...) {  // (nothing here throws; the vectors' destructors free whatever is left)
      }
    }
  };

  /// Particle p's normalised log weight (logw_ is kept up to the shift; step_reordered).
  double normalised_logw(int p) const { return logw_[static_cast<std::size_t>(p)] - logw_shift_; }

  /// The factors and the best child weight of parent p, one of thread w's own parents.
  static MatX& factors(ThreadWork& w, int p) { return w.apar[static_cast<std::size_t>(p - w.first)]; }
  static double best_of(const ThreadWork& w, int p) { return w.best[static_cast<std::size_t>(p - w.first)]; }

  /// A(b, z) = log P(s_b,t = z | s_b,t-1) + log p(o_b | z) for parent p (eqs. 9, 25, 32). The transversal
  /// speed of eq. (10) is taken at the parent's posterior mean x_t-1|t-1 (the paper does not say which
  /// state; the joint PF also uses each particle's x_t-1, the IUKF its predicted mean; at H2's dt = 0.01 s
  /// the three differ negligibly).
  void parent_factors(int p, long k, ThreadWork& w, MatX& A) const {
    if (sight_.speed_dependent()) {
      const auto& L = meas_.layout();
      const State& x = mean_[static_cast<std::size_t>(p)];
      situation::detail::state_transversal_speeds(x.segment(L.position, L.space_dim),
                                                  x.segment(L.velocity, L.space_dim), meas_.anchors(),
                                                  w.speeds, "Rbpf.step");
    }
    const std::uint64_t key = key_[static_cast<std::size_t>(p)];
    std::uint64_t rest = key;
    for (int b = 0; b < B_; ++b) {
      const int prev = static_cast<int>(rest % static_cast<std::uint64_t>(nz_));
      rest /= static_cast<std::uint64_t>(nz_);
      sight_.model(b).transition(k, w.speeds(b), w.T);
      for (int z = 0; z < nz_; ++z) {
        // First step: no previous situation, prior propagated once (pi T).
        const double pr = first_ ? sight_.model(b).initial().dot(w.T.col(z)) : w.T(prev, z);
        A(b, z) = std::log(pr) + Lq_(b, z);
      }
    }
  }

  /// Calls emit(j, key, log weight) for parent p's children j = 0..per-1 (eq. 23; weights of eq. 32 /
  /// first factors of eq. 25), child index p * per + j.
  template <class Emit>
  void for_each_child(int p, ThreadWork& w, Emit emit) {
    const double base = normalised_logw(p);
    int j = 0;
    enumerate_offspring(factors(w, p), static_cast<std::uint64_t>(per_parent_), w.bfw,
                        [&](std::uint64_t key, double s) { emit(j++, key, base + s); });
    for (; j < per_parent_; ++j) emit(j, 0, -kInf);  // not reached: both enumerations emit `per` children
  }

  /// Writes parent p's children into off_* at [p * per, (p + 1) * per).
  void emit_children(int p, ThreadWork& w) {
    const std::size_t u0 = static_cast<std::size_t>(p) * static_cast<std::size_t>(per_parent_);
    for_each_child(p, w, [&](int j, std::uint64_t key, double logw) {
      const std::size_t u = u0 + static_cast<std::size_t>(j);
      off_parent_[u] = p;
      off_key_[u] = key;
      off_logw_[u] = logw;
    });
  }

  /// Calls offer(record) for the children of parent p at or above `cut` (read live; bounded enumeration).
  template <class Offer>
  void offer_children(int p, ThreadWork& w, const double& cut, Offer& offer) {
    const int u0 = p * per_parent_;
    for_each_child(p, w, [&](int j, std::uint64_t key, double logw) {
      if (logw >= cut) offer(ChildRecord{logw, u0 + j, p, key});
    });
  }

  /// Calls offer(record) for the children of parent p whose weight can reach `cut` (read live: offers
  /// raise it) without visiting the others (enumerate_above). Same children, keys and
  /// indices p * per + key as the full enumeration, which it replaces when N_z^B is enumerated.
  template <class Offer>
  void offer_pruned(int p, ThreadWork& w, const double& cut, Offer& offer) {
    const int u0 = p * per_parent_;
    enumerate_above(
        factors(w, p), normalised_logw(p), pow_nz_.data(), w.opt.data(), [&] { return cut; },
        [&](std::uint64_t key, double weight) {
          offer(ChildRecord{weight, u0 + static_cast<int>(key), p, key});
        });
  }

  /// Classical order: every child of every parent into off_*, the parents split evenly over
  /// active_threads(count_) threads. cRBPF-128 expands M = 2 parents: split over two threads, the hand-off
  /// cost more than the work (1.67 us against 0.80 on one thread, H2, an instrumented copy, 2026-12-04).
  int expand_all(long k) {
    const int T = active_threads(count_);
    threads_.pool->parallel_for(T, [&](int th, int, int) {
      const auto [pb, pe] = even_share(count_, th, T);
      ThreadWork& w = *threads_.work[static_cast<std::size_t>(th)];
      w.first = pb;
      for (int p = pb; p < pe; ++p) {
        parent_factors(p, k, w, factors(w, p));
        emit_children(p, w);
      }
    });
    return count_ * per_parent_;
  }

  /// Thread th's contiguous share [b, e) of n items split evenly over T threads.
  static std::pair<int, int> even_share(int n, int th, int T) {
    return {static_cast<int>(static_cast<long long>(n) * th / T),
            static_cast<int>(static_cast<long long>(n) * (th + 1) / T)};
  }

  /// The reordered step (Table V) in one parallel region, phases split by spin barriers (one hand-off
  /// per step; the calling thread is thread 0):
  ///  A. each thread computes the factors, best child and three known child weights of its own parents
  ///     (own_parents), then the threads sweep the parent pairs for neighbours (eq. 29 on the predicted
  ///     means: children keep their parent's kinetic belief, so two children are close exactly when they
  ///     have the same situation and their parents are close) in chunks claimed at run time; thread 0 sets
  ///     the sweep up first;
  ///  B. each thread sorts a contiguous share of the parents (its own parents) by their best child, writes
  ///     every child of its parents with a neighbour and publishes its first shared bound
  ///     (publish_known_bound); then enumerates the children of its other parents that can reach the
  ///     shared cut into its candidate buffer (enumerate_share);
  ///  C. merges (eqs. 29-30) the neighbours' children whose key falls in its key range (children with
  ///     different keys never merge) and keeps the survivors; drops its candidates below the final bound;
  ///  D. thread 0 selects the M heaviest of the threads' candidates and splits the bank (select_kept); the
  ///     others meanwhile update the candidates their bank chunks most likely hold (speculate);
  ///  E. the threads run the UKF bank and the moments of eqs. (27)-(28) in chunks claimed at run time.
  void reordered_region(long k, double t, RbpfStepInfo& info) {
    const double d_min = info.merge_threshold;
    const auto M = static_cast<int>(opt_.num_particles);
    // One region for the whole step: the bank of a step that starts from few parents (the first ones)
    // may still be large enough for the pool.
    const long long most =
        std::min<long long>(M, static_cast<long long>(count_) * static_cast<long long>(per_parent_));
    const int T = active_threads(static_cast<int>(std::max<long long>(count_, most)));
    expand_threads_ = T;
    const bool merge = opt_.merge && count_ > 1;
    region_failed_ = false;
    const unsigned gen = ++region_gen_;
    claims_->sweep.reset();
    threads_.pool->parallel_for(T, [&](int th, int, int) {
      namespace pp = phase_profile;
      pp::mark(th, pp::kRegionStart);
      ThreadWork& w = *threads_.work[static_cast<std::size_t>(th)];
      std::exception_ptr err;
      auto guarded = [&](auto&& f) {
        if (err) return;
        try {
          f();
        } catch (...) {
          err = std::current_exception();
        }
      };
      const std::pair<int, int> own = own_parents(th, T);
      const int pb = own.first, pe = own.second;
      w.first = pb;
      w.nspec = 0;
      w.merged = 0;
      w.crec.clear();
      shared_cut_[static_cast<std::size_t>(th)].q.store(-kInf, std::memory_order_relaxed);  // stale: invalid
      // A. factors, best child and known child weights of the thread's own parents, then the neighbour sweep
      // in chunks claimed at run time (EndClaims: the threads end together whatever their cores' speeds,
      // and the sweep absorbs the factors' imbalance). Thread 0 first sets up the sweep (a serial pass:
      // before the region, both cores waited for it); the others start their factors meanwhile and take
      // more sweep chunks.
      guarded([&] { std::fill(w.near.begin(), w.near.begin() + count_, 0); });
      if (merge && th == 0) {
        sweep_ok_ = false;
        guarded([&] {
          prepare_sweep(d_min);
          sweep_ok_ = true;
        });
        sweep_ready_->publish(gen);  // even after a failure: no one waits forever
        pp::mark(th, pp::kSweepSetup);
      }
      guarded([&] {
        for (int p = pb; p < pe; ++p) parent_bounds(p, k, w);
        pp::mark(th, pp::kFactors);
        if (merge) {
          sweep_ready_->wait(gen);
          if (sweep_ok_)
            for (int front = 0, c; (c = claims_->sweep.claim(th, kSweepChunks, front)) >= 0;)
              sweep_near(c, d_min, w);
          pp::mark(th, pp::kSweep);
        }
      });
      // Every thread arrives at every barrier, even after an exception (no deadlock); the one before the
      // merge is skipped by all threads alike when no parent has a neighbour (they see the same flags).
      barrier_->arrive_and_wait(T);
      pp::mark(th, pp::kWaitFactors);
      // This thread's parents by decreasing best child.
      guarded([&] {
        w.psorted.resize(static_cast<std::size_t>(pe - pb));
        std::iota(w.psorted.begin(), w.psorted.end(), pb);
        std::sort(w.psorted.begin(), w.psorted.end(),
                  [&](int a, int b) { return heavier_first(best_of(w, a), a, best_of(w, b), b); });
      });
      pp::mark(th, pp::kSort);
      // B. children of the parents with a neighbour; first shared bound; enumeration of the others
      guarded([&] {
        for (int p = pb; p < pe; ++p)
          if (is_near(p)) emit_children(p, w);
        publish_known_bound(th, T, w);
      });
      pp::mark(th, pp::kNearChildren);
      barrier_->arrive_and_wait(T);
      pp::mark(th, pp::kWaitBound);
      guarded([&] { enumerate_share(th, T, w); });
      pp::mark(th, pp::kEnumeration);
      // C. merge of the neighbours' children, by key range
      const bool merging = merge && count_near() > 0;
      if (merging) barrier_->arrive_and_wait(T);
      pp::mark(th, pp::kWaitMerge);  // (both marks in every step, so the profile's means add up)
      if (merging) guarded([&] { merge_share(th, T, w); });
      pp::mark(th, pp::kMerge);
      guarded([&] { finish_candidates(T, w); });
      pp::mark(th, pp::kTrim);
      // Selection (serial, on the calling thread) and the split of the bank, then the bank on all threads;
      // the others meanwhile update their likeliest kept children ahead of the bank.
      barrier_->arrive_and_wait(T);
      pp::mark(th, pp::kWaitSelection);
      if (th == 0) {
        guarded([&] { select_kept(info); });
        if (err) region_failed_ = true;
        selected_->publish(gen);  // even after a failure: no one waits forever
        pp::mark(th, pp::kSelection);
      } else {
        guarded([&] { speculate(th, w, t, gen); });
        pp::mark(th, pp::kSpeculation);
        selected_->wait(gen);
      }
      pp::mark(th, pp::kWaitBank);
      if (!region_failed_ && th < bank_threads_)
        guarded([&] {
          bank_part(
              th, t, [&](int i) { return kept_child(i); },
              [&](int i) -> State& { return nmean_[static_cast<std::size_t>(i)]; },
              [&](int i) -> Cov& { return ncov_[static_cast<std::size_t>(i)]; }, nlogw_.data(),
              [&](int c, int b, int e, ThreadWork& tw) { accumulate_moments(c, b, e, tw); });
        });
      pp::mark(th, pp::kBank);
      if (err) std::rethrow_exception(err);
    });
    phase_profile::mark(0, phase_profile::kJoin);
    bank_collect(info);
  }

  /// Thread th's own parents [pb, pe) in the reordered region, whose factors, sorted list and enumeration it
  /// computes. On two threads, thread 0's are the parents that its UKF bank chunks updated in the last step
  /// (parent_split_) and the worker's the rest: each thread then reads the means, weights and factors that
  /// its own core wrote. Before, the factors were claimed in chunks and the
  /// enumeration split the parents evenly, so each crossed over at its own point: rRBPF-128 on H2 took a
  /// median 78.3 us per 2-thread step, 76.9 us with this split (rbpf_speedup.py, 8 alternating lockstep
  /// rounds each, 2026-12-04). A contiguous even split otherwise (first step, three or more threads).
  std::pair<int, int> own_parents(int th, int T) const {
    if (T == 2 && parent_split_ > 0 && parent_split_ < count_)
      return th == 0 ? std::pair<int, int>{0, parent_split_} : std::pair<int, int>{parent_split_, count_};
    return even_share(count_, th, T);
  }

  /// The kept children: the global top M lies in the union of the threads' top-M lists (merged children
  /// included); selected in linear time, ties by index (a strict order, so the set is unique). Zero-weight
  /// children (absorbed, or impossible) are never offered. Then ordered by index (sel_*) and split for the
  /// bank.
  void select_kept(RbpfStepInfo& info) {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    info.merged = 0;
    crec_.clear();
    for (int th = 0; th < expand_threads_; ++th) {
      const ThreadWork& w = *threads_.work[static_cast<std::size_t>(th)];
      info.merged += w.merged;
      crec_.insert(crec_.end(), w.crec.begin(), w.crec.end());
    }
    keep_heaviest(crec_, M, sel_w_, sel_tmp_, sel_ties_);
    // Group the survivors by parent so each parent's sigma points are computed once per thread: a
    // child's index is parent * per + j, so index order groups them.
    order_by_index(crec_);
    const int ns = static_cast<int>(crec_.size());
    info.ukf_runs = ns;
    // The bank also accumulates, per chunk, the moments of eq. (27)-(28) around c = F x_hat_{t-1}
    // (close to the new estimate, so the raw second moment loses no precision), the situation
    // probabilities and the next step's predicted means: no serial pass over the particles after it.
    centre_.noalias() = motion_.F() * est_;
    bank_split(ns, std::min(expand_threads_, active_threads(ns)), [&](int i) { return kept_child(i); });
  }

  /// The i-th kept child (select_kept's order) for the UKF bank.
  BankChild kept_child(int i) const { return bank_child(sel_order_[static_cast<std::size_t>(i)]); }
  static BankChild bank_child(const ChildRecord& r) { return BankChild{r.parent, r.logw, r.key, r.idx}; }

  /// True when parent p has a neighbour within d_min (set by any thread's sweep this step).
  bool is_near(int p) const {
    for (int th = 0; th < expand_threads_; ++th)
      if (threads_.work[static_cast<std::size_t>(th)]->near[static_cast<std::size_t>(p)]) return true;
    return false;
  }
  int count_near() const {
    int n = 0;
    for (int p = 0; p < count_; ++p) n += is_near(p) ? 1 : 0;
    return n;
  }

  /// Factors A of the thread's parent p, its best child's weight and three known child weights (used for
  /// the cut only when p has no neighbour), in the thread's slots (ThreadWork::first).
  void parent_bounds(int p, long k, ThreadWork& w) {
    MatX& A = factors(w, p);
    parent_factors(p, k, w, A);
    const double bp = normalised_logw(p) + A.rowwise().maxCoeff().sum();
    const auto slot = static_cast<std::size_t>(p - w.first);
    w.best[slot] = bp;
    // Three of p's children with known weights: the best, and the best with the anchor of the smallest
    // (then second smallest) gap between its best and second-best condition switched.
    double g1 = kInf, g2 = kInf;
    if (nz_ > 1)
      for (int b = 0; b < B_; ++b) {
        double m1 = -kInf, m2 = -kInf;
        for (int z = 0; z < nz_; ++z) {
          const double a = A(b, z);
          if (a > m1) {
            m2 = m1;
            m1 = a;
          } else if (a > m2) {
            m2 = a;
          }
        }
        const double g = m1 - m2;
        if (g < g1) {
          g2 = g1;
          g1 = g;
        } else if (g < g2) {
          g2 = g;
        }
      }
    const auto u = 3 * slot;
    // The i-th heaviest emitted child weighs at least the i-th known one (i <= children emitted).
    w.known[u] = bp;
    w.known[u + 1] = per_parent_ < 2 ? -kInf : bp - g1;
    w.known[u + 2] = per_parent_ < 3 ? -kInf : bp - g2;
  }

  /// Shared cut of the reordered enumeration. Thread t publishes q_t, a weight such that at least H =
  /// ceil(M / T) distinct children of its parents without a neighbour (never merged, so all survive to
  /// the selection) weigh q_t or more. The threads together then hold T x H >= M such children of weight
  /// >= min_t q_t, so the global M-th weight is at least that: a lighter child cannot be kept, whichever
  /// thread finds it. Without it each thread would fill its own top-M and enumerate about as many children
  /// as one thread does for all parents.
  double shared_bound(int T) const {
    double g = kInf;
    for (int u = 0; u < T; ++u)
      g = std::min(g, shared_cut_[static_cast<std::size_t>(u)].q.load(std::memory_order_relaxed));
    return g;
  }
  int share_size(int T) const { return (opt_.num_particles + T - 1) / T; }
  /// A bound lowered slightly: known weights and enumerated ones are summed in different orders.
  static double lowered(double v) { return std::isfinite(v) ? v - 1e-9 * (1.0 + std::abs(v)) : v; }

  /// First q_th, from the known child weights (parent_bounds) of this thread's parents without a
  /// neighbour: their H-th largest. Read by every thread after the next barrier.
  void publish_known_bound(int th, int T, ThreadWork& w) {
    const auto H = static_cast<std::size_t>(share_size(T));
    std::size_t nk = 0;
    for (const int p : w.psorted) {
      if (is_near(p)) continue;
      const auto u = 3 * static_cast<std::size_t>(p - w.first);
      for (std::size_t i = 0; i < 3; ++i) w.ktmp[nk++] = w.known[u + i];
    }
    double q = -kInf;
    if (nk >= H) {
      std::nth_element(w.ktmp.begin(), w.ktmp.begin() + static_cast<std::ptrdiff_t>(H - 1),
                       w.ktmp.begin() + static_cast<std::ptrdiff_t>(nk), std::greater<double>());
      q = w.ktmp[H - 1];
    }
    shared_cut_[static_cast<std::size_t>(th)].q.store(q, std::memory_order_relaxed);
  }

  /// Appends a candidate to w.crec; when the buffer (kCandidateSlack x M, reserved) is full, keeps its M
  /// heaviest: the thread's share of the global top M is among them.
  static constexpr std::size_t kCandidateSlack = 4;
  void keep_candidate(ThreadWork& w, const ChildRecord& r) const {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    if (w.crec.size() == kCandidateSlack * M) keep_heaviest(w.crec, M, w.sel_w, w.sel_tmp, w.sel_ties);
    w.crec.push_back(r);
  }

  /// End of the thread's expansion: drops the candidates below the shared bound (they cannot be among the
  /// M heaviest) and keeps at most M. With the bound, the threads' lists together exceed M by a few.
  void finish_candidates(int T, ThreadWork& w) const {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    const double floor = lowered(shared_bound(T));
    w.crec.erase(
        std::remove_if(w.crec.begin(), w.crec.end(), [&](const ChildRecord& r) { return r.logw < floor; }),
        w.crec.end());
    keep_heaviest(w.crec, M, w.sel_w, w.sel_tmp, w.sel_ties);
  }

  /// Thread th's part of the reordered enumeration, after every q_t is published: keeps as candidates the
  /// children of its own parents without a neighbour that can reach the cut (the shared bound, below)
  /// (w.psorted: by decreasing best child, so the loop stops at the first parent whose best child cannot
  /// reach it). The thread's own parents, not a share of a global ranking: their factors are in this core's
  /// cache (reading another core's costs more than the imbalance).
  void enumerate_share(int th, int T, ThreadWork& w) {
    using nlosloc::rbpf::detail::may_reach;
    const auto H = static_cast<std::size_t>(share_size(T));
    w.half.clear();
    // others: min of the other threads' q_u as last read (exchanged every kShareEvery parents: a read of
    // another core's slot is a cache miss). A claim stays true once made, so an old read is still a
    // bound; with this thread's live q (the H-th heaviest it has offered) it bounds the global M-th.
    auto read_others = [&] {
      double g = kInf;
      for (int u = 0; u < T; ++u)
        if (u != th)
          g = std::min(g, shared_cut_[static_cast<std::size_t>(u)].q.load(std::memory_order_relaxed));
      return g;
    };
    double others = read_others();
    auto& mine = shared_cut_[static_cast<std::size_t>(th)].q;
    const double known = mine.load(std::memory_order_relaxed);  // this thread's known-weight claim
    double cut = -kInf;
    auto update_cut = [&] {
      const double q = w.half.size() == H ? std::max(known, w.half.front()) : known;
      cut = lowered(std::min(q, others));
    };
    update_cut();
    // Candidates at or above the cut are kept unsorted (finish_candidates trims them); the heap of their H
    // heaviest weights gives this thread's q (one thread: H = M, the running M-th).
    auto offer = [&](const ChildRecord& r) {
      if (!(r.logw > -kInf)) return;
      keep_candidate(w, r);
      if (w.half.size() < H) {
        w.half.push_back(r.logw);
        std::push_heap(w.half.begin(), w.half.end(), std::greater<double>());
      } else if (r.logw > w.half.front()) {
        std::pop_heap(w.half.begin(), w.half.end(), std::greater<double>());
        w.half.back() = r.logw;
        std::push_heap(w.half.begin(), w.half.end(), std::greater<double>());
      } else {
        return;
      }
      update_cut();
    };
    auto publish = [&] {
      if (w.half.size() == H && w.half.front() > mine.load(std::memory_order_relaxed))
        mine.store(w.half.front(), std::memory_order_relaxed);
    };
    int since = 0;
    for (const int p : w.psorted) {
      if (T > 1 && ++since == kShareEvery) {
        since = 0;
        publish();
        others = read_others();
        update_cut();
      }
      if (!may_reach(best_of(w, p), cut)) break;
      if (is_near(p)) continue;
      if (full_enum_)
        offer_pruned(p, w, cut, offer);
      else
        offer_children(p, w, cut, offer);
    }
    publish();  // final: the selection filters with it
  }

  /// xpred_[u] = F x and its leading components xlead_[u] (the neighbour sweep's inputs).
  void set_predicted(std::size_t u, const State& x) {
    xpred_[u].noalias() = motion_.F() * x;
    xlead_[u] = xpred_[u].template head<kLead>();
  }

  /// Chunks of the neighbour sweep (reordered region, phase A), claimed at run time: 1/8 of the pair tests
  /// each.
  static constexpr int kSweepChunks = 8;

  /// Set-up of the neighbour sweep (thread 0, before it sweeps): the predicted means F x_p and their leading
  /// components (unless the last UKF bank left them), the parents in a grid along the first component
  /// (detail::LineGrid: cells of width about d_min, linear; a comparison sort of the parents cost more than
  /// the whole sweep), and a fresh stamp for adj_ (no clearing per step).
  void prepare_sweep(double d_min) {
    if (!xpred_ready_)
      for (int p = 0; p < count_; ++p)
        set_predicted(static_cast<std::size_t>(p), mean_[static_cast<std::size_t>(p)]);
    grid_.build(
        static_cast<std::size_t>(count_), [&](std::size_t p) { return xlead_[p][0]; }, d_min);
    const std::size_t rows = grid_.rows();
    // The leading components in sweep order: the threads then read them in sequence, from this core, and
    // the full predicted means (a line each, written by the cores that ran the bank) only for the pairs
    // that pass them. With the full means copied here instead, the worker's sweep took 4.7 us per step
    // against 2.2 for thread 0's (nlosloc-rbpf-phases --pin 0,1, rRBPF-128 on H2, 2026-12-04).
    slead_.resize(rows);
    for (std::size_t r = 0; r < rows; ++r) slead_[r] = xlead_[static_cast<std::size_t>(grid_.point(r))];
    // Chunks of the rows with about equal numbers of pair tests.
    split_by_cost(
        static_cast<int>(rows), kSweepChunks, [&](int r) { return grid_.cost(static_cast<std::size_t>(r)); },
        sweep_split_.data());
    if (++stamp_ == 0) {  // wrapped: entries of 65536 steps ago would read as this step's
      std::fill(adj_.begin(), adj_.end(), std::uint16_t{0});
      stamp_ = 1;
    }
  }

  /// Orders the kept records by child index (distinct; idx = parent x per + j) into sel_order_, which the
  /// bank reads: a counting pass over the parents (fewer than M + 1), then an insertion sort of each
  /// parent's kept children (a few) by index. Linear in M whatever M x per (the bitmap ranks it replaces
  /// fell back to std::sort when M x per was large, and called a library popcount per word without
  /// -mpopcnt); on the H2 model both take about 1.4 us (nlosloc-rbpf-phases, 2026-12-04).
  void order_by_index(const std::vector<ChildRecord>& v) {
    const std::size_t n = v.size();
    const auto np = static_cast<std::size_t>(count_);
    sel_order_.resize(n);
    // grouped by parent; pstart_[p] is then where group p ends
    detail::counting_scatter(
        n, np, pstart_.data(), [&](std::size_t i) { return v[i].parent; },
        [&](std::size_t i, std::size_t pos) { sel_order_[pos] = v[i]; });
    std::size_t g0 = 0;
    for (std::size_t p = 0; p < np && g0 < n; ++p) {
      const auto g1 = static_cast<std::size_t>(pstart_[p]);
      for (std::size_t i = g0 + 1; i < g1; ++i) {
        const ChildRecord r = sel_order_[i];
        std::size_t j = i;
        for (; j > g0 && sel_order_[j - 1].idx > r.idx; --j) sel_order_[j] = sel_order_[j - 1];
        sel_order_[j] = r;
      }
      g0 = g1;
    }
  }

  /// Chunk c of the sweep: rows [sweep_split_[c], sweep_split_[c + 1]) of the grid, about 1/kSweepChunks of
  /// the pair tests. Marks w.near of both parents and adj_ = stamp_ for each pair within d_min (eq. 29).
  void sweep_near(int c, double d_min, ThreadWork& w) {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    const double d2 = d_min * d_min;
    const auto r0 = static_cast<std::size_t>(sweep_split_[static_cast<std::size_t>(c)]);
    const auto r1 = static_cast<std::size_t>(sweep_split_[static_cast<std::size_t>(c) + 1]);
    for (std::size_t r = r0; r < r1; ++r) {
      const auto a = static_cast<std::size_t>(grid_.point(r));
      grid_.for_candidates(r, [&](std::size_t s) {
        const auto b = static_cast<std::size_t>(grid_.point(s));
        // eq. (29); the leading components' part of the squared distance is at most the whole (a sum of
        // fewer non-negative terms, rounded monotonically), so the pre-test drops no pair
        if ((slead_[r] - slead_[s]).squaredNorm() < d2 && (xpred_[a] - xpred_[b]).squaredNorm() < d2) {
          adj_[a * M + b] = adj_[b * M + a] = stamp_;
          w.near[a] = w.near[b] = 1;
        }
      });
    }
  }

  /// Thread th's part of the merge: the children of parents with a neighbour whose key lies in the
  /// thread's key range, merged greedily (eqs. 29-30; merge_greedy's order, so the result is the serial
  /// merge's), then the survivors kept as candidates (keep_candidate).
  void merge_share(int th, int T, ThreadWork& w) {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    const auto per = static_cast<std::size_t>(per_parent_);
    const std::uint64_t chunk =
        (key_count_ + static_cast<std::uint64_t>(T) - 1) / static_cast<std::uint64_t>(T);
    w.sub.clear();
    w.sub_parent.clear();
    w.sub_key.clear();
    w.sub_logw.clear();
    // With every situation vector enumerated, child j of a parent has key j (enumerate_all's order): the
    // thread's keys are then one slice of each parent's children, and it reads only that slice.
    std::size_t j0 = 0, j1 = per;
    if (full_enum_) {
      j0 = std::min<std::size_t>(per, static_cast<std::size_t>(th) * chunk);
      j1 = std::min<std::size_t>(per, static_cast<std::size_t>(th + 1) * chunk);
    }
    for (int p = 0; p < count_; ++p) {
      if (!is_near(p)) continue;
      const std::size_t u0 = static_cast<std::size_t>(p) * per;
      for (std::size_t i = u0 + j0; i < u0 + j1; ++i) {
        if (!(off_logw_[i] > -kInf) || static_cast<int>(off_key_[i] / chunk) != th) continue;
        w.sub.push_back(static_cast<int>(i));
        w.sub_parent.push_back(p);
        w.sub_key.push_back(off_key_[i]);
        w.sub_logw.push_back(off_logw_[i]);
      }
    }
    if (w.sub.empty()) return;
    w.merged = merge_greedy(
        w.sub_key.data(), w.sub_logw.data(), static_cast<int>(w.sub.size()),
        [&](int a, int b) {
          const auto pa = static_cast<std::size_t>(w.sub_parent[static_cast<std::size_t>(a)]);
          const auto pb = static_cast<std::size_t>(w.sub_parent[static_cast<std::size_t>(b)]);
          return adj_[pa * M + pb] == stamp_;
        },
        w.mws);
    for (std::size_t j = 0; j < w.sub.size(); ++j)  // absorbed children (-inf) are refused
      if (w.sub_logw[j] > -kInf) keep_candidate(w, {w.sub_logw[j], w.sub[j], w.sub_parent[j], w.sub_key[j]});
  }

  void step_reordered(long k, double t, RbpfStepInfo& info) {
    info.offspring = count_ * per_parent_;
    // The bank overwrites xpred_ with the children's predicted means: valid again only once they are
    // the particles (end of this function), so a step that throws leaves it marked stale.
    try {
      reordered_region(k, t, info);
    } catch (...) {
      xpred_ready_ = false;
      throw;
    }
    xpred_ready_ = false;
    const int ns = info.ukf_runs;
    // eq. (33): w_t = w_t|t-1 p(y_t | s_1:t, y_1:t-1), normalised
    const double z = chunk_log_total();
    info.log_likelihood = z;
    State d;
    Cov m2;
    chunk_mixture(z, d, m2);
    set_mixture(d, m2);
    std::swap(mean_, nmean_);
    std::swap(cov_, ncov_);
    std::swap(key_, nkey_);
    std::swap(logw_, nlogw_);
    count_ = ns;
    // Normalised by the shift instead of a pass over nlogw_: thread 0 would write the lines of the worker's
    // chunks, which its core then reads back in the next step's factors and rewrites in the bank after.
    logw_shift_ = z;
    xpred_ready_ = true;
    // The kept children in index order are the new particles: those of thread 0's chunks come first.
    parent_split_ = bank_threads_ == 2 ? bank_front_ : 0;
  }

  /// Reordered summary of bank chunk c, updated particles [b, e): keys, next predicted means, and the
  /// chunk's weighted sums (chunk_moments).
  void accumulate_moments(int c, int b, int e, ThreadWork& w) {
    for (int i = b; i < e; ++i) {
      const auto u = static_cast<std::size_t>(i);
      nkey_[u] = sel_order_[u].key;
      set_predicted(u, nmean_[u]);
    }
    chunk_moments(c, b, e, nlogw_.data(), nmean_.data(), ncov_.data(), nkey_.data(), w);
  }

  /// ChunkMoments of bank chunk c over the updated particles [b, e) (log weights, means, covariances and
  /// keys in these arrays) around centre_, by the thread that updated them: no core reads another's
  /// particles to sum them. The situation weights are summed in the thread's scratch and stored once
  /// (csum_ entries' matrices lie side by side on the heap).
  void chunk_moments(int c, int b, int e, const double* logw, const State* mean, const Cov* cov,
                     const std::uint64_t* key, ThreadWork& w) {
    ChunkMoments& m = csum_[static_cast<std::size_t>(c)];
    m.mmax = -kInf;
    m.m0 = 0.0;
    m.m1.setZero();
    m.m2.setZero();
    w.mprob.setZero();
    for (int i = b; i < e; ++i) m.mmax = std::max(m.mmax, logw[i]);
    if (m.mmax > -kInf)
      for (int i = b; i < e; ++i) {
        const double wi = std::exp(logw[i] - m.mmax);
        if (wi == 0.0) continue;
        const State dx = mean[i] - centre_;
        m.m0 += wi;
        m.m1 += wi * dx;
        m.m2 += wi * (cov[i] + dx * dx.transpose());
        add_situation_weight(key[i], wi, w.mprob);
      }
    m.mprob = w.mprob;
  }

  /// Log of the bank children's summed weights (eq. 25 / 33 normaliser, the step's log-likelihood), from
  /// the chunks' sums in chunk order: the result does not depend on which thread ran which chunk.
  double chunk_log_total() const {
    double z = -kInf;
    for (int c = 0; c < nchunks_; ++c)
      if (const ChunkMoments& m = csum_[static_cast<std::size_t>(c)]; m.m0 > 0.0)
        z = log_add(z, m.mmax + std::log(m.m0));
    if (!std::isfinite(z))
      nlosloc::detail::throw_numerical_error("Rbpf.step: every UKF update failed or had zero likelihood");
    return z;
  }

  /// Centred sums of the bank's children with weights normalised by z, in chunk order: d = sum w (x - c),
  /// m2 = sum w (P + (x - c)(x - c)^T); prob_ = per-anchor situation probabilities.
  void chunk_mixture(double z, State& d, Cov& m2) {
    d.setZero();
    m2.setZero();
    prob_.setZero();
    for (int c = 0; c < nchunks_; ++c) {
      const ChunkMoments& m = csum_[static_cast<std::size_t>(c)];
      if (!(m.m0 > 0.0)) continue;
      const double f = std::exp(m.mmax - z);
      d += f * m.m1;
      m2 += f * m.m2;
      prob_ += f * m.mprob;
    }
  }

  /// Estimate and mixture covariance from chunk_mixture's centred sums.
  void set_mixture(const State& d, const Cov& m2) {
    est_ = centre_ + d;                 // eq. (28)
    est_cov_ = m2 - d * d.transpose();  // eq. (27), moment matched
    nlosloc::detail::symmetrize(est_cov_);
  }

  /// The classical step (Table IV): every child's UKF, each bank chunk summed by the thread that updated
  /// it (chunk_moments), then the merge, which moves the sums with the weights it moves, and the prune.
  /// Summed after the bank on the calling thread instead, cRBPF-128 on H2 spent 8.9 us of a 48.4 us step
  /// on one thread and 10.3 of 35.3 on two in the log-sum-exp, merge and sums (an instrumented copy,
  /// 2026-12-04), the latter reading every child the worker had written.
  void step_classical(long k, double t, RbpfStepInfo& info) {
    const int n = expand_all(k);
    info.offspring = n;
    info.ukf_runs = n;
    centre_.noalias() = motion_.F() * est_;  // near the new estimate: the raw second moment keeps precision
    // Every child's UKF (IV.1), in parent order; eq. (25): add log p(y_t | s_1:t, y_1:t-1).
    run_bank(
        n, t,
        [&](int i) {
          const auto u = static_cast<std::size_t>(i);
          return BankChild{off_parent_[u], off_logw_[u], off_key_[u], i};
        },
        [&](int i) -> State& { return off_mean_[static_cast<std::size_t>(i)]; },
        [&](int i) -> Cov& { return off_cov_[static_cast<std::size_t>(i)]; }, off_logw_.data(), info,
        [&](int c, int b, int e, ThreadWork& w) {
          chunk_moments(c, b, e, off_logw_.data(), off_mean_.data(), off_cov_.data(), off_key_.data(), w);
        });
    const double z = chunk_log_total();
    info.log_likelihood = z;
    Eigen::Map<VecX> lw(off_logw_.data(), n);
    lw.array() -= z;
    // eqs. (27)-(28) over all children, after the merge
    State d;
    Cov m2;
    chunk_mixture(z, d, m2);
    if (opt_.merge) {
      const double dmin = info.merge_threshold;
      info.merged = merge_greedy(
          off_key_.data(), off_logw_.data(), n,
          [&](int a, int b) {
            return (off_mean_[static_cast<std::size_t>(a)] - off_mean_[static_cast<std::size_t>(b)]).norm() <
                   dmin;  // eq. (29)
          },
          mws_,
          [&](int a, int b, double lwb) {
            // eq. (30) moves w_b onto child a, whose mean and covariance stay: the sums of eqs. (27)-(28)
            // move with it (same key, so the situation probabilities do not change)
            const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
            const double wb = std::exp(lwb);
            const State da = off_mean_[ua] - centre_, db = off_mean_[ub] - centre_;
            d += wb * (da - db);
            m2 += wb * ((off_cov_[ua] + da * da.transpose()) - (off_cov_[ub] + db * db.transpose()));
          });
    }
    set_mixture(d, m2);
    select_top(off_logw_.data(), n, opt_.num_particles, sel_);
    const int ns = static_cast<int>(sel_.size());
    double zs = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < ns; ++i)
      zs = log_add(zs, off_logw_[static_cast<std::size_t>(sel_[static_cast<std::size_t>(i)])]);
    for (int i = 0; i < ns; ++i) {
      const auto o = static_cast<std::size_t>(sel_[static_cast<std::size_t>(i)]);
      const auto u = static_cast<std::size_t>(i);
      mean_[u] = off_mean_[o];
      cov_[u] = off_cov_[o];
      key_[u] = off_key_[o];
      logw_[u] = off_logw_[o] - zs;  // renormalised after pruning
    }
    logw_shift_ = 0.0;
    count_ = ns;
  }

  /// Cost of a parent's sigma-point preparation (UkfKernel::prepare) in child updates (finish), for the
  /// split of the bank only (the result does not depend on it). Additive noise: the preparation carries the
  /// sigma points through the motion and the measurements, a child only adds its noise moments (about 1.25
  /// updates). Augmented: each child carries its own sigma set through the measurements and the preparation
  /// is about 0.05 of it. Both measured on H2 (N = 6, B = 6; instrumented bank, commit note); with the
  /// additive ratio for both, the augmented bank of rRBPF-128 ended 15 us later on one thread than the other.
  double prepare_cost() const { return opt_.noise_form == NoiseForm::kAugmented ? 0.05 : 1.25; }

  /// Splits items [0, n) into T contiguous shares of about equal total cost(i) (cost(i) > 0, called twice
  /// per item): split[0] = 0, split[T] = n, and each inner boundary before or after the item that crosses
  /// t/T of the total, whichever is nearer (always after gave the first share half an item more on
  /// average: 1.5 us of an augmented update, when the UKF bank was split so). Used for the neighbour sweep.
  template <class Cost>
  static void split_by_cost(int n, int T, Cost cost, int* split) {
    double total = 0.0;
    for (int i = 0; i < n; ++i) total += cost(i);
    split[0] = 0;
    int t = 1;
    double acc = 0.0;
    for (int i = 0; i < n && t < T; ++i) {
      const double c = cost(i);
      acc += c;
      for (double target; t < T && acc >= (target = total * t / T); ++t)
        split[t] = std::max(split[t - 1], 2.0 * (acc - target) <= c ? i + 1 : i);
    }
    for (; t <= T; ++t) split[t] = n;
  }

  /// Runs the UKF of `n` children (child(i) -> BankChild, in parent order) on the pool and writes prior +
  /// log-likelihood to logw[i]; failures get weight zero. The threads claim the bank's chunks (bank_split)
  /// in turn, and `after(c, b, e, work)` runs on each chunk c = children [b, e) right after its updates.
  template <class Child, class MeanOut, class CovOut, class After>
  void run_bank(int n, double t, Child child, MeanOut mean_out, CovOut cov_out, double* logw,
                RbpfStepInfo& info, After after) {
    bank_split(n, active_threads(n), child);
    threads_.pool->parallel_for(
        bank_threads_, [&](int th, int, int) { bank_part(th, t, child, mean_out, cov_out, logw, after); });
    bank_collect(info);
  }

  /// Chunks of the bank: each (but the two middle ones) at least 1/kMinChunkShare of the cost, at most
  /// kSideChunks on each side of the middle.
  static constexpr int kMinChunkShare = 32, kSideChunks = kMinChunkShare / 2 + 2,
                       kMaxChunks = 2 * kSideChunks;
  /// A new chunk takes about 1/kGuide of the cost left between it and the middle (guided scheduling: large
  /// chunks first, small ones last, so the threads end within a small chunk of each other).
  static constexpr double kGuide = 3.0;

  /// run_bank's serial set-up: cuts the n children into chunks (chunk_, nchunks_) that the threads claim
  /// one at a time, and clears the threads' outcomes. Thread 0 claims from the first chunk on, the others
  /// from the last one back, so the chunks shrink towards the middle of the cost, where the threads meet.
  /// From the ends, each thread updates about the same particles step after step (the kept children come
  /// in parent order): their means and covariances stay in its core's cache instead of crossing over.
  /// Claimed at run time, the chunks follow the cores' speeds: on a shared 2-vCPU host one core often runs
  /// 20-30% slower than the other for a while (nlosloc-rbpf-phases --pin), and the fixed split by cost
  /// this replaces then left the faster thread waiting at the join: 17-25 us of a 135-195 us step in some
  /// runs of nlosloc-rbpf-phases on 2026-12-04. A chunk ends at a parent boundary when one comes within
  /// half its size (a parent's sigma points are prepared once per chunk: prepare_cost() child updates).
  /// The chunks depend on the children only, not on the threads: with the moments summed per chunk and
  /// added in chunk order, a step's result is the same bit for bit on any number of threads, whichever
  /// thread runs which chunk.
  template <class Child>
  void bank_split(int n, int T, Child child) {
    std::fill(thread_fail_.begin(), thread_fail_.end(), 0);
    std::fill(thread_status_.begin(), thread_status_.end(), CholeskyStatus::kOk);
    bank_threads_ = T;
    bank_front_ = 0;
    claims_->bank.reset();  // published by the region's hand-off or barrier
    nchunks_ = 0;
    if (n <= 0) return;
    // One pass over the children marks where each parent's run begins (its sigma points are prepared
    // there); the passes below read the marks instead of calling child() up to four times per child.
    const double first_cost = 1.0 + prepare_cost();
    double total = 0.0;
    for (int i = 0, prev = -1; i < n; ++i) {
      const int p = child(i).parent;
      split_first_[static_cast<std::size_t>(i)] = i == 0 || p != prev ? 1 : 0;
      total += split_first_[static_cast<std::size_t>(i)] != 0 ? first_cost : 1.0;
      prev = p;
    }
    auto cost = [&](int i) { return split_first_[static_cast<std::size_t>(i)] != 0 ? first_cost : 1.0; };
    auto parent_change = [&](int i) { return split_first_[static_cast<std::size_t>(i)] != 0; };  // i-1, i
    const double smallest = total / kMinChunkShare;
    int mid = 0;  // [0, mid) holds at most half the cost
    double before = 0.0;
    while (mid < n && before + cost(mid) <= 0.5 * total) before += cost(mid++);
    // Front half, from the first child on.
    int c = 0;
    chunk_[0] = 0;
    double left = before, acc = 0.0;
    for (int i = 0; i + 1 < mid; ++i) {
      acc += cost(i);
      const double target = std::max(left / kGuide, smallest);
      if (c + 1 < kSideChunks && acc >= target && (parent_change(i + 1) || acc >= 1.5 * target)) {
        chunk_[static_cast<std::size_t>(++c)] = i + 1;
        left -= acc;
        acc = 0.0;
      }
    }
    if (mid > 0) chunk_[static_cast<std::size_t>(++c)] = mid;
    // Back half, from the last child back; its inner boundaries collected last first.
    int r = 0;
    left = total - before;
    acc = 0.0;
    for (int i = n - 1; i > mid; --i) {
      acc += cost(i);
      const double target = std::max(left / kGuide, smallest);
      if (r + 1 < kSideChunks && acc >= target && (parent_change(i) || acc >= 1.5 * target)) {
        back_cut_[static_cast<std::size_t>(r++)] = i;
        left -= acc;
        acc = 0.0;
      }
    }
    while (r > 0) chunk_[static_cast<std::size_t>(++c)] = back_cut_[static_cast<std::size_t>(--r)];
    if (n > mid) chunk_[static_cast<std::size_t>(++c)] = n;
    nchunks_ = c;
  }

  /// Thread th's part of the bank: the chunks it claims, each followed by after(c, b, e, work).
  template <class Child, class MeanOut, class CovOut, class After>
  void bank_part(int th, double t, Child child, MeanOut mean_out, CovOut cov_out, double* logw, After after) {
    auto& ker = *threads_.kernels[static_cast<std::size_t>(th)];
    ThreadWork& w = *threads_.work[static_cast<std::size_t>(th)];
    // The thread's outcome stays in locals and is stored once: the threads' slots of thread_status_ /
    // thread_fail_ share a cache line, and a store per update would bounce it between the cores.
    CholeskyStatus ts = CholeskyStatus::kOk;
    int fails = 0;
    int front_end = 0;  // thread 0: end of its last chunk
    for (int front = 0, c; (c = claims_->bank.claim(th, nchunks_, front)) >= 0;) {
      const int b = chunk_[static_cast<std::size_t>(c)], e = chunk_[static_cast<std::size_t>(c) + 1];
      front_end = e;
      int last = -1;
      CholeskyStatus pst = CholeskyStatus::kOk;
      for (int i = b; i < e; ++i) {
        const BankChild ch = child(i);
        CholeskyStatus st;
        bool ok;
        if (const Speculated* s = find_speculated(w, ch.idx)) {  // updated ahead by this thread
          mean_out(i) = s->x;
          cov_out(i) = s->P;
          logw[i] = s->logw;
          st = s->status;
          ok = s->ok;
        } else {
          ok = update_child(ker, w, ch, t, last, pst, mean_out(i), cov_out(i), logw[i], st);
        }
        ts = nlosloc::detail::worse(ts, st);
        if (!ok) ++fails;
      }
      after(c, b, e, w);
    }
    if (th == 0) bank_front_ = front_end;  // thread 0 claims from the first chunk on: it ran [0, front_end)
    thread_fail_[static_cast<std::size_t>(th)] = fails;
    thread_status_[static_cast<std::size_t>(th)] = ts;
  }

  /// The UKF update of one bank child (Table III): prepares its parent's sigma points unless `last` is that
  /// parent already (status pst), then writes the posterior into (x, P) and prior + log-likelihood into
  /// logw (eq. 25 / 33). Returns false when the update failed (logw = -inf; x, P the prediction when the
  /// parent's factorisation failed); st is the update's factorisation outcome (kFailed when it failed).
  bool update_child(UkfKernel<Motion, Meas>& ker, ThreadWork& w, const BankChild& ch, double t, int& last,
                    CholeskyStatus& pst, State& x, Cov& P, double& logw, CholeskyStatus& st) {
    const int p = ch.parent;
    if (p != last) {
      pst = ker.prepare(motion_, meas_, mean_[static_cast<std::size_t>(p)], cov_[static_cast<std::size_t>(p)],
                        t);
      last = p;
    }
    logw = -std::numeric_limits<double>::infinity();
    st = CholeskyStatus::kFailed;
    if (pst == CholeskyStatus::kFailed) {
      x = ker.predicted_mean();
      P = cov_[static_cast<std::size_t>(p)];
      return false;
    }
    decode_situation(ch.key, nz_, w.s);
    StepResult res;
    const bool ok = ker.finish(w.s, y_, x, P, res);
    if (!ok || !std::isfinite(res.log_likelihood)) return false;
    st = res.status;
    logw = ch.prior + res.log_likelihood;  // eq. (25) / (33)
    return true;
  }

  /// A thread other than the caller, while thread 0 selects (reordered region, before the bank): updates
  /// its candidates of highest index, by decreasing index, until the selection is published (at most
  /// kMaxSpeculated). They are the children of its own parents that its bank chunks, claimed from the last
  /// one back, most likely hold; about nine in ten candidates are kept. The bank then copies an update made
  /// here instead of making it (the same function on the same inputs, so the same result bit for bit); a
  /// child that is not kept, or that another thread's chunk holds, only cost this thread its idle time.
  void speculate(int th, ThreadWork& w, double t, unsigned gen) {
    // the kMaxSpeculated highest indices, highest first, copied without the rest of crec
    const auto n = static_cast<std::size_t>(
        std::partial_sort_copy(w.crec.begin(), w.crec.end(), w.spec_rec.begin(), w.spec_rec.end(),
                               [](const ChildRecord& a, const ChildRecord& b) { return a.idx > b.idx; }) -
        w.spec_rec.begin());
    auto& ker = *threads_.kernels[static_cast<std::size_t>(th)];
    int last = -1;
    CholeskyStatus pst = CholeskyStatus::kOk;
    for (std::size_t i = 0; i < n && !selected_->ready(gen); ++i) {
      const ChildRecord& r = w.spec_rec[i];
      Speculated& s = w.spec[static_cast<std::size_t>(w.nspec)];
      s.idx = r.idx;
      s.ok = update_child(ker, w, bank_child(r), t, last, pst, s.x, s.P, s.logw, s.status);
      ++w.nspec;
    }
  }

  /// This thread's update of child idx made ahead of the bank, or null.
  static const Speculated* find_speculated(const ThreadWork& w, int idx) {
    for (int i = 0; i < w.nspec; ++i)
      if (w.spec[static_cast<std::size_t>(i)].idx == idx) return &w.spec[static_cast<std::size_t>(i)];
    return nullptr;
  }

  void bank_collect(RbpfStepInfo& info) const {
    for (std::size_t th = 0; th < thread_fail_.size(); ++th) {
      info.failures += thread_fail_[th];
      info.status = nlosloc::detail::worse(info.status, thread_status_[th]);
    }
  }

  Motion motion_;
  Meas meas_;
  situation::SightProcess sight_;
  situation::QualityModel quality_;
  RbpfOptions opt_;
  Threads threads_;                       // the pool and each thread's kernel and scratch
  std::unique_ptr<SpinBarrier> barrier_;  // inside reordered_region (pointer: Rbpf stays movable)
  struct alignas(64) SharedCut {          // one cache line per thread
    std::atomic<double> q{-std::numeric_limits<double>::infinity()};
  };
  std::unique_ptr<SharedCut[]> shared_cut_;  // enumerate_share's exchanged bounds (pointer: movable)
  static constexpr int kShareEvery = 4;
  // published by thread 0 once it has set up the region's sweep (prepare_sweep; pointer: movable)
  std::unique_ptr<SpinFlag> sweep_ready_ = std::make_unique<SpinFlag>();
  // published by thread 0 once it has selected the kept children and split the bank (pointer: movable)
  std::unique_ptr<SpinFlag> selected_ = std::make_unique<SpinFlag>();
  unsigned region_gen_ = 0;  // reordered regions run
  bool sweep_ok_ = false;    // prepare_sweep succeeded (read after sweep_ready_)
  int B_ = 0, nz_ = 0, per_parent_ = 0, count_ = 0;
  bool first_ = true;
  double t_ = 0.0, pos_var_ = 0.0;
  double logw_shift_ = 0.0;  // particle i's normalised log weight is logw_[i] - logw_shift_
  long k_ = 0;
  // particles (current and next buffers)
  std::vector<State> mean_, nmean_, xpred_;
  std::vector<Cov> cov_, ncov_;
  std::vector<std::uint64_t> key_, nkey_;
  std::vector<double> logw_, nlogw_;
  // children
  std::vector<int> off_parent_;
  std::vector<std::uint64_t> off_key_;
  std::vector<double> off_logw_;
  std::vector<State> off_mean_;
  std::vector<Cov> off_cov_;
  // merge / select workspace
  // adj_[a M + b] == stamp_: parents a and b are within d_min this step (eq. 29)
  std::vector<std::uint16_t> adj_;
  std::uint16_t stamp_ = 0;
  detail::LineGrid grid_;                // the neighbour sweep's parents along their first component
  std::vector<Lead> xlead_, slead_;      // leading components of xpred_, and in grid_'s row order
  std::vector<int> sweep_split_;         // sweep chunk c: rows [split[c], split[c + 1]) of grid_
  std::uint64_t key_count_ = 0;          // N_z^B: the keys merge_share splits over the threads
  std::vector<int> sel_;                 // classical: selected children (indices into off_*)
  std::vector<ChildRecord> crec_;        // the threads' kept records
  std::vector<double> sel_w_, sel_tmp_;  // keep_heaviest scratch (select_kept)
  std::vector<ChildRecord> sel_ties_;
  std::vector<ChildRecord> sel_order_;  // reordered: the kept children by index (log weight: eq. 32 prior)
  std::vector<int> pstart_;             // order_by_index: each parent's group (counting sort)
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  MergeWorkspace mws_;  // classical RBPF's merge
  // per-thread UKF workspaces
  std::vector<int> thread_fail_;
  std::vector<int> chunk_;                  // bank_split: first child of each chunk (kMaxChunks + 1)
  std::vector<int> back_cut_;               // bank_split: the back half's chunk starts, last first
  std::vector<unsigned char> split_first_;  // bank_split: 1 where a parent's run of children begins
  int nchunks_ = 0;                         // chunks of the last bank
  int bank_front_ = 0;                      // the last bank's thread 0 ran children [0, bank_front_)
  // own_parents on two threads: thread 0's are [0, it), set by each reordered step (a rejected step leaves
  // the particles and so their split); used only when inside (0, count_), so a reset needs no clearing
  int parent_split_ = 0;
  struct Claims {  // run-time chunk claims of the reordered region and of the bank (pointer: movable)
    EndClaims sweep, bank;
  };
  std::unique_ptr<Claims> claims_ = std::make_unique<Claims>();
  std::vector<ChunkMoments> csum_;             // each chunk's moments (reordered step)
  State centre_;                               // c of chunk_moments
  int expand_threads_ = 1, bank_threads_ = 1;  // threads of the last expansion / UKF bank
  bool region_failed_ = false;                 // reordered_region: the selection threw (no bank)
  bool xpred_ready_ = false;                   // xpred_ holds F x of the current particles
  bool full_enum_ = false;                     // every situation vector is a child (N_z^B <= max_offspring)
  std::vector<std::uint64_t> pow_nz_;          // N_z^b
  std::vector<CholeskyStatus> thread_status_;
  MatX Lq_, prob_;
  VecX y_;
  State est_;
  Cov est_cov_;
};

}  // namespace nlosloc::rbpf
