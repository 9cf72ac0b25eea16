#pragma once
/// \file rbpf.hpp
/// Rao-Blackwellized particle filter of Huerta et al. 2009 (Sec. V-A, V-B): a deterministic particle filter
/// over the situation vectors s_1:t (eqs. 20-25) with a bank of UKFs for the kinetic state given each
/// particle's situation history (eq. 26, Table III), merge and select (eqs. 29-31), in the classical order
/// (Table IV: expand, UKF every child, weight, merge/select) or the reordered one (Table V: expand, weight by
/// prior and quality statistic, merge/select, then UKF only the M survivors).
///
/// Choices the paper leaves open (documented here and in the report):
///  - the UKF is the additive-noise form with each row's exact noise mean and variance under the particle's
///    situation (Ukf of filters/ukf.hpp); eq. (25)'s likelihood is its Gaussian predictive N(y; y_hat, S);
///  - the first step has no previous situation: its transition prior is the chains' prior propagated once,
///    p(s_1) = pi T (the particle set starts as one particle of weight one);
///  - in the reordered order the children are compared (eq. 29) by their predicted means F x_{t-1};
///  - eq. (31)'s position variance is the trace of the position block of the last mixture covariance;
///  - estimate (eq. 28), mixture covariance and situation probabilities: over all weighted children in the
///    classical order (as eq. 28 sums over i and k), over the M updated particles in the reordered order.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/rbpf/merge.hpp"
#include "nlosloc/rbpf/offspring.hpp"
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
  int threads = 1;                     ///< threads of the UKF bank (pool created once)
  SigmaScheme scheme = SigmaScheme::scaled();  ///< sigma points of the per-particle UKF
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

  Rbpf(const Motion& motion, const Meas& meas, situation::SightProcess sight, situation::QualityModel quality,
       const Gaussian<N>& initial, const RbpfOptions& options = {}, double t0 = 0.0)
      : motion_(motion),
        meas_(meas),
        sight_(std::move(sight)),
        quality_(std::move(quality)),
        opt_(options),
        pool_(std::make_unique<ThreadPool>(options.threads)) {
    ::nlosloc::detail::check_layout<N>(meas);
    meas.check_ready();
    NLOSLOC_ENSURE(options.num_particles >= 1,
                   "options.num_particles: expected M >= 1, got " + std::to_string(options.num_particles));
    NLOSLOC_ENSURE(options.max_offspring >= 1, "options.max_offspring: expected >= 1");
    NLOSLOC_ENSURE(options.variant == RbpfVariant::kClassical || options.variant == RbpfVariant::kReordered,
                   "options.variant: unknown RbpfVariant");
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
    options.scheme.validate(N);
    B_ = meas.num_anchors();
    nz_ = meas.num_conditions();
    const std::uint64_t total = situation_count(nz_, B_);
    NLOSLOC_ENSURE(total != 0, "sight: N_z^B does not fit in 62 bits; reduce the anchors per filter");
    per_parent_ = static_cast<int>(std::min<std::uint64_t>(total, options.max_offspring));
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
    adj_.resize(static_cast<std::size_t>(M) * static_cast<std::size_t>(M));
    sel_.reserve(cap);
    mws_.reserve(cap);
    sub_.reserve(cap);
    sub_key_.reserve(cap);
    sub_logw_.reserve(cap);
    near_.assign(static_cast<std::size_t>(M), 0);
    best_.assign(static_cast<std::size_t>(M), 0.0);
    known_.assign(3 * static_cast<std::size_t>(M), 0.0);
    ktmp_ = known_;
    byx_.reserve(static_cast<std::size_t>(M));
    porder_.reserve(static_cast<std::size_t>(M));
    apar_.assign(static_cast<std::size_t>(M), MatX::Zero(B_, nz_));
    for (int t = 0; t < pool_->size(); ++t) {
      kernels_.emplace_back(std::make_unique<UkfKernel<Motion, Meas>>(meas_, options.scheme));
      auto w = std::make_unique<ThreadWork>();
      w->T.resize(nz_, nz_);
      w->speeds.setZero(B_);
      w->s.setZero(B_);
      w->cand.reserve(static_cast<std::size_t>(M));
      if (static_cast<std::uint64_t>(per_parent_) < total)
        w->best.reserve(B_, nz_, static_cast<std::uint64_t>(per_parent_));
      work_.push_back(std::move(w));
    }
    thread_fail_.assign(static_cast<std::size_t>(pool_->size()), 0);
    thread_status_.assign(static_cast<std::size_t>(pool_->size()), CholeskyStatus::kOk);
    Lq_.resize(B_, nz_);
    cand_.reserve(cap + static_cast<std::size_t>(M) * static_cast<std::size_t>(pool_->size()));
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
    first_ = true;
    t_ = t0;
    k_ = 0;
    est_ = initial.mean;
    est_cov_ = initial.cov;
    prob_.setZero();
    for (int b = 0; b < B_; ++b) prob_.row(b) = sight_.model(b).initial().transpose();
    pos_var_ = position_variance(initial.cov);
  }

  /// One iteration with measurements y (size rows; NaN = missing) and quality statistics o (size B;
  /// NaN = missing). Throws NumericalError (state unchanged) when every UKF update fails.
  RbpfStepInfo step(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) {
    nlosloc::detail::check_measurement(y, meas_.rows());
    nlosloc::detail::ensure_shape(o, B_, 1, "o");
    y_ = y;
    quality_.log_likelihood_table(o, Lq_);
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
    return info;
  }

  // ---- results ------------------------------------------------------------------------------------
  /// Number of particles carried to the next step (<= M).
  int num_particles() const { return count_; }
  /// Normalised log weight of particle i.
  double log_weight(int i) const { return logw_.at(static_cast<std::size_t>(check(i))); }
  /// Normalised weights (size num_particles()).
  VecX weights() const {
    VecX w(count_);
    for (int i = 0; i < count_; ++i) w(i) = std::exp(logw_[static_cast<std::size_t>(i)]);
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

  /// Per-thread scratch of the expansion and the UKF bank.
  struct ThreadWork {
    MatX T;
    VecX speeds;
    VecXi s;
    std::vector<int> cand;    // top-M children of this thread's share of the parents without a neighbour
    BestFirstWorkspace best;  // bounded enumeration (reserved at construction when it is used)
  };

  /// A(b, z) = log P(s_b,t = z | s_b,t-1) + log p(o_b | z) for parent p (eqs. 9, 25, 32).
  void parent_factors(int p, long k, ThreadWork& w, MatX& A) const {
    if (sight_.speed_dependent()) {
      const auto& L = meas_.layout();
      const State& x = mean_[static_cast<std::size_t>(p)];
      situation::transversal_speeds(x.segment(L.position, L.space_dim), x.segment(L.velocity, L.space_dim),
                                    meas_.anchors(), w.speeds);
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

  /// Writes parent p's children into off_* at [p * per, (p + 1) * per) (eq. 23; weights of eq. 32 / first
  /// factors of eq. 25) and offers each to `top` when given.
  void emit_children(int p, ThreadWork& w, TopSelector* top,
                     double floor = -std::numeric_limits<double>::infinity()) {
    const int per = per_parent_;
    const double base = logw_[static_cast<std::size_t>(p)];
    auto u = static_cast<std::size_t>(p) * static_cast<std::size_t>(per);
    const std::size_t end = u + static_cast<std::size_t>(per);
    enumerate_offspring(apar_[static_cast<std::size_t>(p)], static_cast<std::uint64_t>(per), w.best,
                        [&](std::uint64_t key, double s) {
                          off_parent_[u] = p;
                          off_key_[u] = key;
                          off_logw_[u] = base + s;
                          if (top && off_logw_[u] >= floor) top->offer(static_cast<int>(u));
                          ++u;
                        });
    for (; u < end; ++u) {  // not reached: both enumerations emit exactly `per` children
      off_parent_[u] = p;
      off_key_[u] = 0;
      off_logw_[u] = -std::numeric_limits<double>::infinity();
    }
  }

  /// Classical order: every child of every parent into off_*, parents split over the pool.
  int expand_all(long k) {
    pool_->parallel_for(count_, [&](int pb, int pe, int th) {
      ThreadWork& w = *work_[static_cast<std::size_t>(th)];
      for (int p = pb; p < pe; ++p) {
        parent_factors(p, k, w, apar_[static_cast<std::size_t>(p)]);
        emit_children(p, w, nullptr);
      }
    });
    return count_ * per_parent_;
  }

  /// Reordered order: marks the parents with a neighbour within d_min (eq. 29 on the predicted means:
  /// children keep their parent's kinetic belief, so two children are close exactly when they have the
  /// same situation and their parents are close), writes every child of those (the merge needs them) and,
  /// per thread, the M heaviest children of the other parents into w.cand. A parent whose best child
  /// (its weight plus sum_b max_z A(b, z)) is lighter than the thread's M-th kept child cannot contribute
  /// and is not enumerated; parents are visited by decreasing best child so this cut comes early.
  int expand_reordered(long k, double d_min) {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    std::fill(near_.begin(), near_.end(), 0);
    if (opt_.merge) mark_near_parents(d_min);
    // Factors, best child and the near parents' children, parents split over the pool.
    pool_->parallel_for(count_, [&](int pb, int pe, int th) {
      ThreadWork& w = *work_[static_cast<std::size_t>(th)];
      for (int p = pb; p < pe; ++p) {
        MatX& A = apar_[static_cast<std::size_t>(p)];
        parent_factors(p, k, w, A);
        const double bp = logw_[static_cast<std::size_t>(p)] + A.rowwise().maxCoeff().sum();
        best_[static_cast<std::size_t>(p)] = bp;
        // Three of p's children with known weights: the best, and the best with the anchor of the
        // smallest (then second smallest) gap between its best and second-best condition switched.
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
        const auto u = 3 * static_cast<std::size_t>(p);
        // The i-th heaviest emitted child weighs at least the i-th known one (i <= children emitted).
        const bool skip = near_[static_cast<std::size_t>(p)] != 0;
        known_[u] = skip ? -kInf : bp;
        known_[u + 1] = skip || per_parent_ < 2 ? -kInf : bp - g1;
        known_[u + 2] = skip || per_parent_ < 3 ? -kInf : bp - g2;
        if (near_[static_cast<std::size_t>(p)]) emit_children(p, w, nullptr);
      }
    });
    // tau: the M-th largest of those known weights (of distinct children of parents without a
    // neighbour) is a lower bound of the M-th heaviest child among those parents; lighter children and
    // parents whose best child is lighter are skipped. Slightly lowered for the summation order.
    double tau = -kInf;
    const auto nk = 3 * static_cast<std::size_t>(count_);
    std::copy(known_.begin(), known_.begin() + static_cast<std::ptrdiff_t>(nk), ktmp_.begin());
    if (nk >= M) {
      std::nth_element(ktmp_.begin(), ktmp_.begin() + static_cast<std::ptrdiff_t>(M - 1),
                       ktmp_.begin() + static_cast<std::ptrdiff_t>(nk), std::greater<double>());
      const double v = ktmp_[M - 1];
      if (std::isfinite(v)) tau = v - 1e-9 * (1.0 + std::abs(v));
    }
    // The other parents by decreasing best child, dealt round-robin to the threads so each gets an even
    // share of the parents that survive the cut below.
    porder_.clear();
    for (int p = 0; p < count_; ++p)
      if (!near_[static_cast<std::size_t>(p)]) porder_.push_back(p);
    std::sort(porder_.begin(), porder_.end(), [&](int a, int b) {
      const double ba = best_[static_cast<std::size_t>(a)], bb = best_[static_cast<std::size_t>(b)];
      return ba != bb ? ba > bb : a < b;
    });
    const int T = pool_->size();
    pool_->parallel_for(T, [&](int tb, int te, int) {
      for (int th = tb; th < te; ++th) {
        ThreadWork& w = *work_[static_cast<std::size_t>(th)];
        TopSelector top(off_logw_.data(), static_cast<int>(M), w.cand);
        for (std::size_t j = static_cast<std::size_t>(th); j < porder_.size();
             j += static_cast<std::size_t>(T)) {
          const int p = porder_[j];
          // The margin covers the different summation order of the children's weights.
          const double bp = best_[static_cast<std::size_t>(p)];
          if (bp + 1e-9 * (1.0 + std::abs(bp)) < tau) break;
          if (top.full() && bp + 1e-9 * (1.0 + std::abs(bp)) < top.threshold()) break;
          emit_children(p, w, &top, tau);
        }
      }
    });
    return count_ * per_parent_;
  }

  /// near_[p] = 1 when parent p's predicted mean F x_p is within d_min of another's (eq. 29), with the
  /// pairs in adj_. Sorted sweep on the first state component (|dx_0| <= ||dx||), so only candidate pairs
  /// are measured.
  void mark_near_parents(double d_min) {
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    const double d2 = d_min * d_min;
    for (int p = 0; p < count_; ++p)
      xpred_[static_cast<std::size_t>(p)].noalias() = motion_.F() * mean_[static_cast<std::size_t>(p)];
    std::fill(adj_.begin(), adj_.end(), 0);
    byx_.resize(static_cast<std::size_t>(count_));
    for (int p = 0; p < count_; ++p) byx_[static_cast<std::size_t>(p)] = p;
    std::sort(byx_.begin(), byx_.end(), [&](int a, int b) {
      return xpred_[static_cast<std::size_t>(a)][0] < xpred_[static_cast<std::size_t>(b)][0];
    });
    for (std::size_t i = 0; i < byx_.size(); ++i) {
      const auto a = static_cast<std::size_t>(byx_[i]);
      for (std::size_t j = i + 1; j < byx_.size(); ++j) {
        const auto b = static_cast<std::size_t>(byx_[j]);
        if (xpred_[b][0] - xpred_[a][0] >= d_min) break;
        if ((xpred_[a] - xpred_[b]).squaredNorm() < d2) {  // eq. (29)
          adj_[a * M + b] = adj_[b * M + a] = 1;
          near_[a] = near_[b] = 1;
        }
      }
    }
  }

  void step_reordered(long k, double t, RbpfStepInfo& info) {
    const int n = expand_reordered(k, info.merge_threshold);
    info.offspring = n;
    // Children of parents with a neighbour: merged (eqs. 29-30), then all candidates for the selection.
    const auto M = static_cast<std::size_t>(opt_.num_particles);
    const auto per = static_cast<std::size_t>(per_parent_);
    sub_.clear();
    sub_key_.clear();
    sub_logw_.clear();
    for (int p = 0; p < count_; ++p)
      if (near_[static_cast<std::size_t>(p)])
        for (std::size_t i = static_cast<std::size_t>(p) * per; i < (static_cast<std::size_t>(p) + 1) * per;
             ++i) {
          sub_.push_back(static_cast<int>(i));
          sub_key_.push_back(off_key_[i]);
          sub_logw_.push_back(off_logw_[i]);
        }
    if (!sub_.empty()) {
      info.merged = merge_greedy(
          sub_key_.data(), sub_logw_.data(), static_cast<int>(sub_.size()),
          [&](int a, int b) {
            const auto pa = static_cast<std::size_t>(
                off_parent_[static_cast<std::size_t>(sub_[static_cast<std::size_t>(a)])]);
            const auto pb = static_cast<std::size_t>(
                off_parent_[static_cast<std::size_t>(sub_[static_cast<std::size_t>(b)])]);
            return adj_[pa * M + pb] != 0;
          },
          mws_);
      for (std::size_t j = 0; j < sub_.size(); ++j)
        off_logw_[static_cast<std::size_t>(sub_[j])] = sub_logw_[j];
    }
    // The global top M lies in the merged children and the threads' top-M lists of the others (whose
    // weights the merge did not touch).
    cand_.assign(sub_.begin(), sub_.end());
    for (const auto& w : work_) cand_.insert(cand_.end(), w->cand.begin(), w->cand.end());
    select_top_of(
        off_logw_.data(), static_cast<int>(cand_.size()),
        [this](int j) { return cand_[static_cast<std::size_t>(j)]; }, opt_.num_particles, sel_);
    // Group the survivors by parent so each parent's sigma points are computed once per thread: a
    // child's index is parent * per + rank, so index order groups them (std::sort: no buffer allocated).
    std::sort(sel_.begin(), sel_.end());
    const int ns = static_cast<int>(sel_.size());
    info.ukf_runs = ns;
    run_bank(
        ns, t, [&](int i) { return sel_[static_cast<std::size_t>(i)]; },
        [&](int i) -> State& { return nmean_[static_cast<std::size_t>(i)]; },
        [&](int i) -> Cov& { return ncov_[static_cast<std::size_t>(i)]; }, nlogw_.data(), info);
    for (int i = 0; i < ns; ++i)
      nkey_[static_cast<std::size_t>(i)] =
          off_key_[static_cast<std::size_t>(sel_[static_cast<std::size_t>(i)])];
    // eq. (33): w_t = w_t|t-1 p(y_t | s_1:t, y_1:t-1), normalised (log-sum-exp)
    Eigen::Map<VecX> lw(nlogw_.data(), ns);
    const double z = log_sum_exp(lw);
    if (!std::isfinite(z))
      nlosloc::detail::throw_numerical_error("Rbpf.step: every UKF update failed or had zero likelihood");
    lw.array() -= z;
    info.log_likelihood = z;
    std::swap(mean_, nmean_);
    std::swap(cov_, ncov_);
    std::swap(key_, nkey_);
    std::swap(logw_, nlogw_);
    count_ = ns;
    summarise(
        count_, [&](int i) -> const State& { return mean_[static_cast<std::size_t>(i)]; },
        [&](int i) -> const Cov& { return cov_[static_cast<std::size_t>(i)]; },
        [&](int i) { return key_[static_cast<std::size_t>(i)]; },
        [&](int i) { return logw_[static_cast<std::size_t>(i)]; });
  }

  void step_classical(long k, double t, RbpfStepInfo& info) {
    const int n = expand_all(k);
    info.offspring = n;
    info.ukf_runs = n;
    // Every child's UKF (IV.1), in parent order; eq. (25): add log p(y_t | s_1:t, y_1:t-1).
    run_bank(
        n, t, [](int i) { return i; },
        [&](int i) -> State& { return off_mean_[static_cast<std::size_t>(i)]; },
        [&](int i) -> Cov& { return off_cov_[static_cast<std::size_t>(i)]; }, off_logw_.data(), info);
    Eigen::Map<VecX> lw(off_logw_.data(), n);
    const double z = log_sum_exp(lw);
    if (!std::isfinite(z))
      nlosloc::detail::throw_numerical_error("Rbpf.step: every UKF update failed or had zero likelihood");
    lw.array() -= z;
    info.log_likelihood = z;
    if (opt_.merge) {
      const double d = info.merge_threshold;
      info.merged = merge_greedy(
          off_key_.data(), off_logw_.data(), n,
          [&](int a, int b) {
            return (off_mean_[static_cast<std::size_t>(a)] - off_mean_[static_cast<std::size_t>(b)]).norm() <
                   d;  // eq. (29)
          },
          mws_);
    }
    // eq. (28) and the mixture (27) over all children
    summarise(
        n, [&](int i) -> const State& { return off_mean_[static_cast<std::size_t>(i)]; },
        [&](int i) -> const Cov& { return off_cov_[static_cast<std::size_t>(i)]; },
        [&](int i) { return off_key_[static_cast<std::size_t>(i)]; },
        [&](int i) { return off_logw_[static_cast<std::size_t>(i)]; });
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
    count_ = ns;
  }

  /// Runs the UKF of `n` children (child(i) -> index into off_*, in parent order) on the pool and adds the
  /// log-likelihood to logw[i] (starting from off_logw_ of the child); failures get weight zero.
  template <class Child, class MeanOut, class CovOut>
  void run_bank(int n, double t, Child child, MeanOut mean_out, CovOut cov_out, double* logw,
                RbpfStepInfo& info) {
    std::fill(thread_fail_.begin(), thread_fail_.end(), 0);
    std::fill(thread_status_.begin(), thread_status_.end(), CholeskyStatus::kOk);
    pool_->parallel_for(n, [&](int b, int e, int th) {
      auto& ker = *kernels_[static_cast<std::size_t>(th)];
      VecXi& s = work_[static_cast<std::size_t>(th)]->s;
      int last = -1;
      CholeskyStatus pst = CholeskyStatus::kOk;
      StepResult res;
      for (int i = b; i < e; ++i) {
        const auto c = static_cast<std::size_t>(child(i));
        const int p = off_parent_[c];
        if (p != last) {
          pst = ker.prepare(motion_, meas_, mean_[static_cast<std::size_t>(p)],
                            cov_[static_cast<std::size_t>(p)], t);
          last = p;
        }
        const double prior = off_logw_[c];
        if (pst == CholeskyStatus::kFailed) {
          logw[i] = -std::numeric_limits<double>::infinity();
          mean_out(i) = ker.predicted_mean();
          cov_out(i) = cov_[static_cast<std::size_t>(p)];
          ++thread_fail_[static_cast<std::size_t>(th)];
          thread_status_[static_cast<std::size_t>(th)] = CholeskyStatus::kFailed;
          continue;
        }
        decode_situation(off_key_[c], nz_, s);
        const bool ok = ker.finish(s, y_, mean_out(i), cov_out(i), res);
        auto& ts = thread_status_[static_cast<std::size_t>(th)];
        ts = nlosloc::detail::worse(ts, res.status);
        if (!ok || !std::isfinite(res.log_likelihood)) {
          logw[i] = -std::numeric_limits<double>::infinity();
          ++thread_fail_[static_cast<std::size_t>(th)];
          ts = CholeskyStatus::kFailed;
        } else {
          logw[i] = prior + res.log_likelihood;  // eq. (25) / (33)
        }
      }
    });
    for (std::size_t th = 0; th < thread_fail_.size(); ++th) {
      info.failures += thread_fail_[th];
      info.status = nlosloc::detail::worse(info.status, thread_status_[th]);
    }
  }

  /// Estimate (eq. 28), moment-matched mixture covariance (eq. 27) and per-anchor situation probabilities
  /// of n weighted Gaussians (log weights normalised up to a common constant).
  template <class MeanAt, class CovAt, class KeyAt, class LogwAt>
  void summarise(int n, MeanAt mean_at, CovAt cov_at, KeyAt key_at, LogwAt logw_at) {
    double z = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) z = log_add(z, logw_at(i));
    est_.setZero();
    prob_.setZero();
    for (int i = 0; i < n; ++i) {
      const double w = std::exp(logw_at(i) - z);
      if (w == 0.0) continue;
      est_ += w * mean_at(i);  // eq. (28)
      std::uint64_t key = key_at(i);
      for (int b = 0; b < B_; ++b) {
        prob_(b, static_cast<Eigen::Index>(key % static_cast<std::uint64_t>(nz_))) += w;
        key /= static_cast<std::uint64_t>(nz_);
      }
    }
    est_cov_.setZero();
    for (int i = 0; i < n; ++i) {
      const double w = std::exp(logw_at(i) - z);
      if (w == 0.0) continue;
      const State d = mean_at(i) - est_;
      est_cov_ += w * (cov_at(i) + d * d.transpose());  // eq. (27), second moment
    }
    nlosloc::detail::symmetrize(est_cov_);
  }

  Motion motion_;
  Meas meas_;
  situation::SightProcess sight_;
  situation::QualityModel quality_;
  RbpfOptions opt_;
  std::unique_ptr<ThreadPool> pool_;  // owned through a pointer: workers keep its address; Rbpf stays movable
  int B_ = 0, nz_ = 0, per_parent_ = 0, count_ = 0;
  bool first_ = true;
  double t_ = 0.0, pos_var_ = 0.0;
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
  std::vector<char> adj_, near_;
  std::vector<int> sel_, sub_, cand_, byx_, porder_;
  std::vector<double> best_;          // best child log weight per parent
  std::vector<double> known_, ktmp_;  // three known child weights per parent, and scratch
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<MatX> apar_;  // per-parent factors A (B x N_z)
  std::vector<std::uint64_t> sub_key_;
  std::vector<double> sub_logw_;
  MergeWorkspace mws_;
  // per-thread UKF workspaces
  std::vector<std::unique_ptr<UkfKernel<Motion, Meas>>> kernels_;
  std::vector<std::unique_ptr<ThreadWork>> work_;
  std::vector<int> thread_fail_;
  std::vector<CholeskyStatus> thread_status_;
  MatX Lq_, prob_;
  VecX y_;
  State est_;
  Cov est_cov_;
};

}  // namespace nlosloc::rbpf
