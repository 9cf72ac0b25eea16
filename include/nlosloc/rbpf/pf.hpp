#pragma once
/// \file pf.hpp
/// Joint particle filter over (x, s), the "PF" of Huerta et al. 2009 Sec. VI-B: bootstrap proposal (x from
/// the motion model, eq. 4; s from the sight chains, eqs. 9, 15-18), weights by the exact measurement noise
/// densities p(y | x, s) (Table VIII/X, non-Gaussian allowed) times the quality likelihood p(o | s), then
/// either systematic resampling (when the effective sample size falls below a threshold) or the paper's
/// merge-and-select adapted to sampled particles.
///
/// Layout: structure of arrays (state component d of particle i at x[d * M + i], anchor b's condition at
/// s[b * M + i]), double buffers for resampling, all allocated at construction: step() does not allocate
/// (except the optional merge, which sorts in preallocated buffers).
///
/// Merge-select for sampled particles (the paper applies the RBPF's rule, eqs. 29-30, to its 1e6-particle
/// PF without details): particles are bucketed by situation vector and by the cell floor(x / d_min) of the
/// state grid, and inside a bucket the greedy merge of merge.hpp moves weight from lighter to heavier
/// particles within d_min (pairs split by a cell boundary are not merged: a documented approximation that
/// keeps the cost linear); the merged set is then brought back to M particles by systematic resampling.
///
/// Row types: every row whose noise is one distribution selected by its own anchor (TOA, RTOA, AOA, AOA
/// phase, linear). TDOA (difference of two noises) and two-way ranging rows are rejected: their densities
/// have no closed form here.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/filters/common.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/rbpf/merge.hpp"
#include "nlosloc/rbpf/offspring.hpp"
#include "nlosloc/rbpf/thread_pool.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace nlosloc::rbpf {

/// Selection step of the joint PF.
enum class PfResampling {
  kSystematic = 0,  ///< systematic resampling when ESS < ess_threshold * M
  kMergeSelect = 1  ///< merge (eqs. 29-30, bucketed) then systematic resampling back to M, every step
};

/// Settings of ParticleFilter.
struct PfOptions {
  int num_particles = 10000;  ///< M >= 1
  PfResampling resampling = PfResampling::kSystematic;
  double ess_threshold = 0.5;     ///< in [0, 1]; 1 resamples every step, 0 never
  double merge_threshold = -1.0;  ///< d_min of kMergeSelect; negative: eq. (31) from the position variance
  int threads = 1;                ///< threads (pool created once); results depend on the thread count
  std::uint64_t seed = 0;         ///< seed of the per-thread generators (stream = thread index)
};

/// What one PF step reports.
struct PfStepInfo {
  double log_likelihood = 0.0;  ///< log mean of the incremental weights: estimate of log p(y_t, o_t | past)
  double ess = 0.0;             ///< effective sample size after weighting, before resampling
  bool resampled = false;
  int merged = 0;
};

/// Systematic resampling: writes M ancestor indices for normalised weights w (size n) using one uniform
/// u0 in (0, 1): the j-th pointer is (j + u0) / M. Unbiased: E[copies of i] = M w_i.
template <class W>
void systematic_resample(const W& w, int n, int M, double u0, int* out) {
  double c = w(0);
  int i = 0;
  for (int j = 0; j < M; ++j) {
    const double u = (static_cast<double>(j) + u0) / static_cast<double>(M);
    while (u > c && i < n - 1) c += w(++i);
    out[j] = i;
  }
}

/// Bootstrap particle filter over (x, s).
template <class Motion, class Meas = MeasurementStack>
class ParticleFilter {
 public:
  static constexpr int N = Motion::kDim;
  using State = Vec<N>;
  using Cov = Mat<N, N>;

  ParticleFilter(const Motion& motion, const Meas& meas, situation::SightProcess sight,
                 situation::QualityModel quality, const Gaussian<N>& initial, const PfOptions& options = {},
                 double t0 = 0.0)
      : motion_(motion),
        meas_(meas),
        sight_(std::move(sight)),
        quality_(std::move(quality)),
        opt_(options),
        pool_(std::make_unique<ThreadPool>(options.threads)) {
    ::nlosloc::detail::check_layout<N>(meas);
    meas.check_ready();
    NLOSLOC_ENSURE(options.num_particles >= 1, "options.num_particles: expected M >= 1");
    NLOSLOC_ENSURE(options.ess_threshold >= 0.0 && options.ess_threshold <= 1.0,
                   "options.ess_threshold: expected a value in [0, 1]");
    NLOSLOC_ENSURE(
        options.resampling == PfResampling::kSystematic || options.resampling == PfResampling::kMergeSelect,
        "options.resampling: unknown PfResampling");
    NLOSLOC_ENSURE(std::isfinite(options.merge_threshold),
                   "options.merge_threshold: expected a finite value");
    NLOSLOC_ENSURE(sight_.num_anchors() == meas.num_anchors(), "sight: expected one chain per anchor");
    NLOSLOC_ENSURE(sight_.num_conditions() == meas.num_conditions() &&
                       quality_.num_conditions() == meas.num_conditions(),
                   "sight, quality: expected as many conditions as the measurements");
    NLOSLOC_ENSURE(meas.num_conditions() <= 255, "measurements: at most 255 conditions");
    NLOSLOC_ENSURE(!sight_.speed_dependent() || meas.layout().velocity >= 0,
                   "sight: a speed-dependent chain needs a velocity in the state layout");
    for (int i = 0; i < meas.rows(); ++i) {
      const RowKind k = meas.row(i).kind;
      NLOSLOC_ENSURE(k != RowKind::kTdoa && k != RowKind::kTwrTau && k != RowKind::kTwrT,
                     "measurements: the joint PF supports TOA, RTOA, AOA and linear rows (row " +
                         std::to_string(i) + " is " + to_string(k) + ")");
    }
    M_ = options.num_particles;
    B_ = meas.num_anchors();
    nz_ = meas.num_conditions();
    const auto M = static_cast<std::size_t>(M_);
    x_.resize(M * N);
    nx_.resize(M * N);
    s_.resize(M * static_cast<std::size_t>(B_));
    ns_.resize(M * static_cast<std::size_t>(B_));
    logw_.resize(M_);
    w_.resize(M_);
    anc_.resize(M);
    // Square root of Q (PSD, possibly singular: Huerta eq. 6 has no position noise): Q = G G^T with only the
    // non-zero eigen-directions, so a step draws rank(Q) normals.
    Eigen::SelfAdjointEigenSolver<Cov> es(motion.Q());
    Eigen::Matrix<double, N, Eigen::Dynamic> G(N, 0);
    const double tol = 1e-14 * std::max(1.0, es.eigenvalues().cwiseAbs().maxCoeff());
    for (int j = 0; j < N; ++j)
      if (es.eigenvalues()(j) > tol) {
        G.conservativeResize(Eigen::NoChange, G.cols() + 1);
        G.col(G.cols() - 1) = es.eigenvectors().col(j) * std::sqrt(es.eigenvalues()(j));
      }
    G_ = G;
    for (int t = 0; t < pool_->size(); ++t) {
      rng_.emplace_back(options.seed, static_cast<std::uint64_t>(t));
      z_.emplace_back(VecX::Zero(meas.rows()));
    }
    thread_sum_.assign(static_cast<std::size_t>(pool_->size()), 0.0);
    // Rows whose every condition is Normal or Rayleigh get a closed-form log density: the logs of the
    // Rayleigh residuals are summed as the log of one product per particle (one log instead of one per row).
    fastlik_ = true;
    lik_.resize(static_cast<std::size_t>(meas.rows()) * static_cast<std::size_t>(nz_));
    for (int i = 0; i < meas.rows(); ++i)
      for (int z = 0; z < nz_; ++z) {
        const noise::Distribution& d = meas.noise(i, z);
        RowLik& l =
            lik_[static_cast<std::size_t>(i) * static_cast<std::size_t>(nz_) + static_cast<std::size_t>(z)];
        if (d.holds<noise::Normal>()) {
          const auto& n = d.get<noise::Normal>();
          l = {false, n.mean(), 0.5 / n.variance(), -0.5 * std::log(2.0 * kPi * n.variance())};
        } else if (d.holds<noise::Rayleigh>()) {
          const double s2 = d.get<noise::Rayleigh>().scale() * d.get<noise::Rayleigh>().scale();
          l = {true, 0.0, 0.5 / s2, -std::log(s2)};  // log(r / s^2) - r^2 / (2 s^2)
        } else {
          fastlik_ = false;
        }
      }
    fast2d_ = meas.layout().space_dim == 2 && nz_ == 2 && meas.layout().velocity >= 0;
    for (int b = 0; b < B_; ++b) fast2d_ = fast2d_ && sight_.model(b).speed_dependent();
    Lq_.resize(B_, nz_);
    cum_.resize(static_cast<std::size_t>(B_) * static_cast<std::size_t>(nz_ * nz_));
    T_.resize(nz_, nz_);
    prob_.resize(B_, nz_);
    y_.resize(meas.rows());
    if (options.resampling == PfResampling::kMergeSelect) {
      mkey_.resize(M);
      morder_.resize(M);
    }
    reset(initial, t0);
  }

  /// Draws M particles: x ~ N(initial), s_b ~ the chains' priors; equal weights.
  void reset(const Gaussian<N>& initial, double t0 = 0.0) {
    initial.validate("initial");
    NLOSLOC_ENSURE(std::isfinite(t0), "t0: expected a finite time (s)");
    Cov L;
    double jit = 0.0;
    if (nlosloc::detail::factor_state_cov(initial.cov, L, &jit) == CholeskyStatus::kFailed)
      nlosloc::detail::throw_numerical_error("ParticleFilter.reset: initial.cov not positive definite");
    Rng& r = rng_[0];
    r.reseed(opt_.seed, 0);
    for (int i = 0; i < M_; ++i) {
      State u;
      for (int d = 0; d < N; ++d) u(d) = r.normal();
      const State x = initial.mean + L * u;
      for (int d = 0; d < N; ++d) x_[idx(d, i)] = x(d);
      for (int b = 0; b < B_; ++b)
        s_[sidx(b, i)] = static_cast<std::uint8_t>(sight_.model(b).sample_initial(r));
    }
    for (int t = 1; t < pool_->size(); ++t)
      rng_[static_cast<std::size_t>(t)].reseed(opt_.seed, static_cast<std::uint64_t>(t));
    logw_.setConstant(-std::log(static_cast<double>(M_)));
    t_ = t0;
    k_ = 0;
    summarise();
  }

  /// One step with measurements y (NaN = missing) and quality statistics o (size B, NaN = missing).
  PfStepInfo step(const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o) {
    nlosloc::detail::check_measurement(y, meas_.rows());
    nlosloc::detail::ensure_shape(o, B_, 1, "o");
    y_ = y;
    quality_.log_likelihood_table(o, Lq_);
    const long k = k_ + 1;
    const double t = t_ + motion_.dt();
    const bool speed = sight_.speed_dependent();
    if (!speed) {
      // Fixed chains: cumulative transition rows per anchor for this step (eq. 16 schedule).
      for (int b = 0; b < B_; ++b) {
        sight_.model(b).transition(k, 0.0, T_);
        for (int m = 0; m < nz_; ++m) {
          double c = 0.0;
          for (int j = 0; j < nz_; ++j) cum_[cidx(b, m, j)] = (c += T_(m, j));
        }
      }
    }
    std::fill(thread_sum_.begin(), thread_sum_.end(), 0.0);
    pool_->parallel_for(M_, [&](int b0, int e0, int th) { propagate_weight(b0, e0, th, k, t, speed); });
    PfStepInfo info;
    // Incremental weights were added to the normalised log weights: their log-sum-exp is log p(y, o | past).
    const double z = log_sum_exp(logw_);
    if (!std::isfinite(z))
      nlosloc::detail::throw_numerical_error("ParticleFilter.step: every particle has zero likelihood");
    logw_.array() -= z;
    info.log_likelihood = z;
    t_ = t;
    k_ = k;
    summarise(true);                    // also sets w_ (normalised weights)
    info.ess = 1.0 / w_.squaredNorm();  // estimate before selection (lower variance)
    if (opt_.resampling == PfResampling::kMergeSelect) {
      info.merged = merge_cells();
      w_ = logw_.array().exp();
      w_ /= w_.sum();
      resample();
      info.resampled = true;
    } else if (info.ess < opt_.ess_threshold * static_cast<double>(M_)) {
      resample();
      info.resampled = true;
    }
    return info;
  }

  int num_particles() const { return M_; }
  /// Weighted mean of the particles (after the last weighting).
  const State& estimate() const { return est_; }
  const Cov& covariance() const { return est_cov_; }
  Gaussian<N> belief() const { return {est_, est_cov_}; }
  /// P(s_b = z), B x N_z.
  const MatX& situation_probabilities() const { return prob_; }
  VecXi sight_estimate() const {
    VecXi s(B_);
    for (int b = 0; b < B_; ++b) prob_.row(b).maxCoeff(&s(b));
    return s;
  }
  /// Particle states as an N x M matrix (a copy), situations B x M, normalised log weights.
  MatX particles() const { return Eigen::Map<const MatX>(x_.data(), M_, N).transpose(); }
  Eigen::MatrixXi situations() const {
    Eigen::MatrixXi s(B_, M_);
    for (int b = 0; b < B_; ++b)
      for (int i = 0; i < M_; ++i) s(b, i) = s_[sidx(b, i)];
    return s;
  }
  const VecX& log_weights() const { return logw_; }
  double time() const { return t_; }
  const PfOptions& options() const { return opt_; }

 private:
  std::size_t idx(int d, int i) const {
    return static_cast<std::size_t>(d) * static_cast<std::size_t>(M_) + static_cast<std::size_t>(i);
  }
  std::size_t sidx(int b, int i) const {
    return static_cast<std::size_t>(b) * static_cast<std::size_t>(M_) + static_cast<std::size_t>(i);
  }
  std::size_t cidx(int b, int m, int j) const {
    return (static_cast<std::size_t>(b) * static_cast<std::size_t>(nz_) + static_cast<std::size_t>(m)) *
               static_cast<std::size_t>(nz_) +
           static_cast<std::size_t>(j);
  }

  void propagate_weight(int b0, int e0, int th, long k, double t, bool speed) {
    Rng& rng = rng_[static_cast<std::size_t>(th)];
    VecX& z = z_[static_cast<std::size_t>(th)];
    const auto& F = motion_.F();
    const int r = static_cast<int>(G_.cols());
    const auto& L = meas_.layout();
    const int m = meas_.rows();
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, N, 1> u(r);
    Mat<2, 2> T2;
    MatX Tb;
    for (int i = b0; i < e0; ++i) {
      State x;
      for (int d = 0; d < N; ++d) x(d) = x_[idx(d, i)];
      // Situation transition from the previous state's transversal speed (eqs. 9-10, 15-18 / 16).
      for (int b = 0; b < B_; ++b) {
        std::uint8_t& sb = s_[sidx(b, i)];
        if (fast2d_) {
          // 2-D, two conditions: eq. (10) as |d x v| / |d| and the switching probability in closed form
          const double dx = x(L.position) - meas_.anchors()(b, 0),
                       dy = x(L.position + 1) - meas_.anchors()(b, 1);
          const double vx = x(L.velocity), vy = x(L.velocity + 1);
          const double d2 = dx * dx + dy * dy;
          const double w =
              d2 > 0.0 ? std::abs(dx * vy - dy * vx) / std::sqrt(d2) : std::sqrt(vx * vx + vy * vy);
          if (rng.uniform() < situation::speed_switch_probability(sight_.model(b), sb, w))
            sb = static_cast<std::uint8_t>(1 - sb);
        } else if (speed) {
          const double w = situation::transversal_speed(x.segment(L.position, L.space_dim),
                                                        x.segment(L.velocity, L.space_dim),
                                                        meas_.anchors().row(b).transpose());
          sb = static_cast<std::uint8_t>(sight_.model(b).sample_next(sb, k, w, rng));
        } else {
          const double uu = rng.uniform();
          int j = 0;
          while (j < nz_ - 1 && uu >= cum_[cidx(b, sb, j)]) ++j;
          sb = static_cast<std::uint8_t>(j);
        }
      }
      // x_t = F x_{t-1} + u_t (eq. 4), u_t = G n with n standard normal of size rank(Q).
      for (int j = 0; j < r; ++j) u(j) = rng.normal();
      State xn = F * x;
      xn.noalias() += G_ * u;
      for (int d = 0; d < N; ++d) x_[idx(d, i)] = xn(d);
      // log p(y | x, s) with each row's own noise density, and log p(o | s).
      meas_.predict(xn, t, z);
      double lw = 0.0;
      if (fastlik_) {
        double prod = 1.0;
        for (int row = 0; row < m; ++row) {
          if (std::isnan(y_(row))) continue;
          const int a = meas_.row(row).anchor;
          const int c = a < 0 ? 0 : s_[sidx(a, i)];
          double res = y_(row) - z(row);
          if (meas_.is_angle(row)) res = wrap_angle(res);
          const RowLik& l = lik_[static_cast<std::size_t>(row) * static_cast<std::size_t>(nz_) +
                                 static_cast<std::size_t>(c)];
          if (l.rayleigh) {
            prod *= res > 0.0 ? res : 0.0;  // outside the support: weight 0
            lw += l.c - l.inv2 * res * res;
          } else {
            const double e = res - l.mu;
            lw += l.c - l.inv2 * e * e;
          }
        }
        lw += std::log(prod);
      } else {
        for (int row = 0; row < m; ++row) {
          if (std::isnan(y_(row))) continue;
          const int a = meas_.row(row).anchor;
          const int c = a < 0 ? 0 : s_[sidx(a, i)];
          double res = y_(row) - z(row);
          if (meas_.is_angle(row)) res = wrap_angle(res);
          lw += meas_.noise(row, c).log_pdf(res);
        }
      }
      for (int b = 0; b < B_; ++b) lw += Lq_(b, s_[sidx(b, i)]);
      logw_(i) += lw;
    }
  }

  /// `normalised`: logw_ already sums to one in probability (skips a log-sum-exp pass).
  void summarise(bool normalised = false) {
    if (normalised)
      w_ = logw_.array().exp();
    else
      w_ = (logw_.array() - log_sum_exp(logw_)).exp();
    // one pass: weighted first and second moments (eq. 28 analogue for sampled particles)
    State m1 = State::Zero();
    Cov m2 = Cov::Zero();
    prob_.setZero();
    for (int i = 0; i < M_; ++i) {
      const double wi = w_(i);
      if (wi == 0.0) continue;
      State x;
      for (int d = 0; d < N; ++d) x(d) = x_[idx(d, i)];
      m1 += wi * x;
      m2.noalias() += wi * x * x.transpose();
      for (int b = 0; b < B_; ++b) prob_(b, s_[sidx(b, i)]) += wi;
    }
    est_ = m1;
    est_cov_ = m2 - m1 * m1.transpose();
    nlosloc::detail::symmetrize(est_cov_);
  }

  void resample() {
    const double u0 = rng_[0].uniform();
    systematic_resample(w_, M_, M_, u0, anc_.data());
    for (int d = 0; d < N; ++d)
      for (int i = 0; i < M_; ++i) nx_[idx(d, i)] = x_[idx(d, anc_[static_cast<std::size_t>(i)])];
    for (int b = 0; b < B_; ++b)
      for (int i = 0; i < M_; ++i) ns_[sidx(b, i)] = s_[sidx(b, anc_[static_cast<std::size_t>(i)])];
    std::swap(x_, nx_);
    std::swap(s_, ns_);
    logw_.setConstant(-std::log(static_cast<double>(M_)));
  }

  /// Bucketed greedy merge (see the file comment); returns the number of absorbed particles.
  int merge_cells() {
    const auto& L = meas_.layout();
    const double pos_var = est_cov_.diagonal().segment(L.position, L.space_dim).sum();
    const double d =
        opt_.merge_threshold >= 0.0 ? opt_.merge_threshold : default_merge_threshold(pos_var, M_);
    if (!(d > 0.0)) return 0;
    for (int i = 0; i < M_; ++i) {
      std::uint64_t h = 1469598103934665603ULL;  // FNV-1a over the situation and the grid cell
      for (int b = 0; b < B_; ++b) h = (h ^ s_[sidx(b, i)]) * 1099511628211ULL;
      for (int e = 0; e < N; ++e)
        h = (h ^ static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(x_[idx(e, i)] / d)))) *
            1099511628211ULL;
      mkey_[static_cast<std::size_t>(i)] = h;
    }
    return merge_greedy(
        mkey_.data(), logw_.data(), M_,
        [&](int a, int b) {
          for (int bb = 0; bb < B_; ++bb)
            if (s_[sidx(bb, a)] != s_[sidx(bb, b)]) return false;  // eq. (29): different situation
          double d2 = 0.0;
          for (int e = 0; e < N; ++e) {
            const double v = x_[idx(e, a)] - x_[idx(e, b)];
            d2 += v * v;
          }
          return d2 < d * d;
        },
        mws_);
  }

  Motion motion_;
  Meas meas_;
  situation::SightProcess sight_;
  situation::QualityModel quality_;
  PfOptions opt_;
  std::unique_ptr<ThreadPool> pool_;  // stable address for the workers; the filter stays movable
  int M_ = 0, B_ = 0, nz_ = 0;
  bool fast2d_ = false;
  struct RowLik {
    bool rayleigh;
    double mu, inv2, c;
  };
  std::vector<RowLik> lik_;
  bool fastlik_ = false;  // all chains speed-dependent LOS/NLOS in 2-D: closed-form switch probability
  double t_ = 0.0;
  long k_ = 0;
  std::vector<double> x_, nx_;
  std::vector<std::uint8_t> s_, ns_;
  VecX logw_, w_;
  std::vector<int> anc_;
  Eigen::Matrix<double, N, Eigen::Dynamic> G_;
  std::vector<Rng> rng_;
  std::vector<VecX> z_;
  std::vector<double> thread_sum_, cum_;
  MatX Lq_, T_, prob_;
  VecX y_;
  std::vector<std::uint64_t> mkey_;
  std::vector<int> morder_;
  MergeWorkspace mws_;
  State est_;
  Cov est_cov_;
};

}  // namespace nlosloc::rbpf
