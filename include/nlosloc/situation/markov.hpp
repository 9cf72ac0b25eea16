#pragma once
/// \file markov.hpp
/// Sight-condition Markov models. Each anchor's condition s in {0 (LOS), 1, ..., N_z - 1 (NLOS types)}
/// follows its own Markov chain, independent of the other anchors (Huerta eq. 9). Two kinds of chain:
///  - a fixed row-stochastic N_z x N_z matrix Q, optionally allowed to switch only every K_sight steps
///    (Grisales eq. 16);
///  - the two-state (LOS/NLOS) chain whose probabilities follow from the mobile's transversal speed w.r.t.
///    the anchor (Huerta eqs. 10, 14-15), with the several-transitions-per-interval form (eq. 17) and
///    its memoryless limit (eq. 18).
/// `SightModel` wraps either behind one interface: `transition(step, w)` for filters, `sample_next()` for
/// simulation. `SightProcess` holds one `SightModel` per anchor.
/// Convention everywhere: T(m, j) = P(s_t = j | s_{t-1} = m) (rows sum to one).
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nlosloc/core/random.hpp"
#include "nlosloc/core/types.hpp"

namespace nlosloc::situation {

namespace detail {
/// Throws unless T is square, finite, non-negative, with rows summing to one (within 1e-9).
inline void ensure_stochastic(const MatX& T, const char* name) {
  using nlosloc::detail::throw_invalid_argument;
  if (T.rows() < 1 || T.rows() != T.cols())
    throw_invalid_argument(std::string(name) + ": expected a square N_z x N_z matrix (N_z >= 1), got " +
                           nlosloc::detail::shape_str(T.rows(), T.cols()));
  nlosloc::detail::ensure_finite(T, name);
  if ((T.array() < 0.0).any())
    throw_invalid_argument(std::string(name) + ": expected non-negative transition probabilities");
  for (Eigen::Index r = 0; r < T.rows(); ++r)
    if (std::abs(T.row(r).sum() - 1.0) > 1e-9)
      throw_invalid_argument(std::string(name) + ": row " + std::to_string(r) + " sums to " +
                             std::to_string(T.row(r).sum()) + ", expected 1");
}

/// Draws j with probability row(j) (row sums to one; the last index absorbs rounding).
template <class Row>
int sample_row(const Row& row, Rng& rng) {
  const double u = rng.uniform();
  double c = 0.0;
  const int n = static_cast<int>(row.size());
  for (int j = 0; j < n - 1; ++j) {
    c += row(j);
    if (u < c) return j;
  }
  return n - 1;
}

/// Stationary distribution pi = pi T of an ergodic chain: solves (T^T - I) pi = 0 with sum(pi) = 1.
inline VecX stationary_distribution(const MatX& T) {
  const Eigen::Index n = T.rows();
  MatX A = T.transpose() - MatX::Identity(n, n);
  A.row(n - 1).setOnes();  // replace one (redundant) balance equation by the normalisation
  VecX b = VecX::Zero(n);
  b(n - 1) = 1.0;
  const Eigen::ColPivHouseholderQR<MatX> qr(A);
  // A reducible chain (e.g. T = I) has no unique answer: A is singular and the solve would return one of
  // many stationary vectors, arbitrarily; fall back to uniform, as documented.
  if (qr.rank() < n) return VecX::Constant(n, 1.0 / static_cast<double>(n));
  VecX pi = qr.solve(b);
  if (!pi.allFinite() || (pi.array() < -1e-9).any()) return VecX::Constant(n, 1.0 / static_cast<double>(n));
  pi = pi.cwiseMax(0.0);
  return pi / pi.sum();
}
}  // namespace detail

/// Transversal speed of the mobile w.r.t. an anchor (Huerta eq. 10): the norm of the velocity minus its
/// projection on p - q. p, v, q have the same size (2-D or 3-D). Returns ||v|| when p == q, and NaN or inf
/// when an input is not finite (a NaN position used to read as "on the anchor" and gave ||v||).
template <class DP, class DV, class DQ>
double transversal_speed(const Eigen::MatrixBase<DP>& p, const Eigen::MatrixBase<DV>& v,
                         const Eigen::MatrixBase<DQ>& q) {
  const auto d = (p - q).eval();
  const double d2 = d.squaredNorm();
  if (d2 == 0.0) return v.norm();
  return (v - (d.dot(v) / d2) * d).norm();  // eq. (10)
}

/// Transversal speed w.r.t. every anchor (rows of `anchors`, B x D) into `out` (size B).
template <class DP, class DV>
void transversal_speeds(const Eigen::MatrixBase<DP>& p, const Eigen::MatrixBase<DV>& v, const MatX& anchors,
                        Eigen::Ref<VecX> out) {
  for (Eigen::Index b = 0; b < anchors.rows(); ++b)
    out(b) = transversal_speed(p, v, anchors.row(b).transpose());
}

namespace detail {
/// transversal_speeds at a filter's own state (eq. 10): a speed that is not finite means the state has
/// overflowed, a numerical failure of the filter (NumericalError naming `who`), not a bad argument.
template <class DP, class DV>
void state_transversal_speeds(const Eigen::MatrixBase<DP>& p, const Eigen::MatrixBase<DV>& v,
                              const MatX& anchors, Eigen::Ref<VecX> out, const char* who) {
  transversal_speeds(p, v, anchors, out);
  for (Eigen::Index b = 0; b < out.size(); ++b)
    if (!std::isfinite(out(b)))
      nlosloc::detail::throw_numerical_error(
          std::string(who) + ": the transversal speed (eq. 10) w.r.t. anchor " + std::to_string(b) + " is " +
          std::to_string(out(b)) + ": the state is not finite or has overflowed (the filter is unchanged)");
}
}  // namespace detail

/// Which form of the speed-dependent two-state chain to use.
enum class SpeedModel {
  kSingle = 0,      ///< Huerta eq. (15): at most one change per interval (valid for w dt << E{L})
  kMultiple = 1,    ///< Huerta eq. (17): any number of instantaneous changes per interval (default)
  kMemoryless = 2,  ///< Huerta eq. (18): the limit w dt >> E{L}; rows equal (p_L, p_N)
};

namespace detail {
/// The transversal distance a = w dt of one interval (Huerta eq. 14), the speed chains' arguments checked
/// (named) once for eqs. (15) and (17).
inline double transversal_distance(double w, double dt, double mean_los, double mean_nlos) {
  nlosloc::detail::ensure_nonnegative(w, "w");
  nlosloc::detail::ensure_positive(dt, "dt");
  nlosloc::detail::ensure_positive(mean_los, "mean_los");
  nlosloc::detail::ensure_positive(mean_nlos, "mean_nlos");
  const double a = w * dt;
  NLOSLOC_ENSURE(std::isfinite(a), "w, dt: the transversal distance w * dt overflows (w = " +
                                       std::to_string(w) + ", dt = " + std::to_string(dt) + ")");
  return a;
}
}  // namespace detail

/// Two-state transition matrix of Huerta eq. (15) for transversal speed w (m/s), interval dt (s) and mean
/// LOS / NLOS lengths (m). Order [LOS, NLOS].
inline Mat<2, 2> speed_transition_single(double w, double dt, double mean_los, double mean_nlos) {
  const double a = detail::transversal_distance(w, dt, mean_los, mean_nlos);
  Mat<2, 2> T;
  T(0, 0) = mean_los / (a + mean_los);    // p_LL, eq. (15)
  T(0, 1) = a / (a + mean_los);           // p_LN
  T(1, 0) = a / (a + mean_nlos);          // p_NL (eq. 14)
  T(1, 1) = mean_nlos / (a + mean_nlos);  // p_NN
  return T;
}

/// Two-state matrix of Huerta eq. (17): a round trip LOS->NLOS->LOS is instantaneous, so every interval
/// sums the geometric series rho = 1 / (1 - p_LN p_NL) over them. With a = w dt and the eq. (15) entries,
/// rho = (a + L_L)(a + L_N) / D, D = a (L_L + L_N) + L_L L_N, so p'_LN = p_LN p_NN rho = a L_N / D and
/// p'_NL = a L_L / D: computed so (the form speed_switch_probability uses), since 1 - p_LN p_NL cancels
/// to 0 at large a (w = 1e17 m/s gave inf entries, and the row sums drifted by 3e-9 at a / L = 1e8).
inline Mat<2, 2> speed_transition_multiple(double w, double dt, double mean_los, double mean_nlos) {
  const double a = detail::transversal_distance(w, dt, mean_los, mean_nlos), ll = mean_los, ln = mean_nlos;
  const double d = a * (ll + ln) + ll * ln;
  Mat<2, 2> T;
  T(0, 1) = a * ln / d;         // p'_LN, eq. (17)
  T(0, 0) = ll * (a + ln) / d;  // p'_LL = p_LL rho
  T(1, 0) = a * ll / d;         // p'_NL
  T(1, 1) = ln * (a + ll) / d;  // p'_NN = p_NN rho
  return T;
}

/// Memoryless limit of eq. (17) (Huerta eq. 18): every row is (p_L, p_N) = (L_LOS, L_NLOS) / (L_LOS +
/// L_NLOS). Also the stationary distribution of eq. (17) at every speed, hence the natural initial prior.
/// Not that of eq. (15) (single change per interval): H1's lengths at w = 200 m/s give (0.82, 0.18) there,
/// against (0.857, 0.143); at H1's 10 m/s, 0.855. (The paper attributes this limit to w dt << E{L};
/// eq. 17 actually tends to it for w dt >> E{L}.)
inline Mat<2, 2> speed_transition_memoryless(double mean_los, double mean_nlos) {
  nlosloc::detail::ensure_positive(mean_los, "mean_los");
  nlosloc::detail::ensure_positive(mean_nlos, "mean_nlos");
  const double pl = mean_los / (mean_los + mean_nlos);
  Mat<2, 2> T;
  T << pl, 1.0 - pl, pl, 1.0 - pl;  // eq. (18)
  return T;
}

/// One anchor's sight model: a fixed N_z-state chain (with K_sight schedule) or the speed-dependent
/// two-state chain. A value type; cheap to copy.
class SightModel {
 public:
  /// Fixed chain with row-stochastic `transition` (N_z x N_z). Changes are allowed only at steps k that are
  /// multiples of `k_sight` >= 1 (Grisales eq. 16); at other steps the matrix is the identity.
  /// `initial` (size N_z, sums to one) is the prior of s_0; empty: the stationary distribution of Q.
  static SightModel fixed(const MatX& transition, long k_sight = 1, const VecX& initial = VecX()) {
    detail::ensure_stochastic(transition, "transition");
    NLOSLOC_ENSURE(k_sight >= 1, "k_sight: expected an integer >= 1, got " + std::to_string(k_sight));
    SightModel m;
    m.kind_ = Kind::kFixed;
    m.Q_ = transition;
    m.k_sight_ = k_sight;
    m.set_initial(initial);
    return m;
  }

  /// Speed-dependent LOS/NLOS chain (Huerta eqs. 14-18) with mean LOS/NLOS lengths (m), interval dt (s).
  /// `initial` empty: (p_L, p_N) of eq. (18).
  static SightModel speed_dependent(double mean_los, double mean_nlos, double dt,
                                    SpeedModel form = SpeedModel::kMultiple, const VecX& initial = VecX()) {
    nlosloc::detail::ensure_positive(mean_los, "mean_los");
    nlosloc::detail::ensure_positive(mean_nlos, "mean_nlos");
    nlosloc::detail::ensure_positive(dt, "dt");
    NLOSLOC_ENSURE(
        form == SpeedModel::kSingle || form == SpeedModel::kMultiple || form == SpeedModel::kMemoryless,
        "form: unknown SpeedModel");
    SightModel m;
    m.kind_ = Kind::kSpeed;
    m.mean_los_ = mean_los;
    m.mean_nlos_ = mean_nlos;
    m.dt_ = dt;
    m.form_ = form;
    m.Q_ = speed_transition_memoryless(mean_los, mean_nlos);
    m.set_initial(initial);
    return m;
  }

  /// Number of sight conditions N_z.
  int num_conditions() const { return static_cast<int>(Q_.rows()); }
  /// True for the speed-dependent model (its matrix depends on the transversal speed).
  bool speed_dependent() const { return kind_ == Kind::kSpeed; }
  /// K_sight of the fixed model (1 for the speed-dependent one).
  long k_sight() const { return k_sight_; }
  /// The fixed model's Q (Grisales eq. 16); for the speed model its memoryless matrix (eq. 18).
  const MatX& base_matrix() const { return Q_; }
  /// Prior of s_0 (size N_z).
  const VecX& initial() const { return initial_; }
  /// True when a change may happen at step k (k >= 1 is the transition from k-1 to k).
  bool is_change_step(long k) const { return kind_ == Kind::kSpeed || k_sight_ <= 1 || k % k_sight_ == 0; }

  /// Transition matrix for the step from k-1 to k, given the transversal speed w (m/s; ignored by the fixed
  /// model). Writes N_z x N_z into `out` (resized if needed; no allocation when already the right size).
  void transition(long k, double w, MatX& out) const {
    const int n = num_conditions();
    if (out.rows() != n || out.cols() != n) out.resize(n, n);
    if (kind_ == Kind::kFixed) {
      if (is_change_step(k))
        out = Q_;  // Grisales eq. (16), k = r K_sight
      else
        out.setIdentity();  // eq. (16), otherwise
      return;
    }
    out = speed_matrix(w);
  }
  /// Convenience form of transition() returning the matrix.
  MatX transition(long k, double w = 0.0) const {
    MatX T;
    transition(k, w, T);
    return T;
  }

  /// Draws s_k given s_{k-1} = `current` (simulation). Same arguments as transition().
  int sample_next(int current, long k, double w, Rng& rng) const {
    NLOSLOC_ENSURE(current >= 0 && current < num_conditions(),
                   "current: expected a condition in [0, N_z), got " + std::to_string(current));
    if (kind_ == Kind::kFixed) {
      if (!is_change_step(k)) return current;
      return detail::sample_row(Q_.row(current), rng);
    }
    return detail::sample_row(speed_matrix(w).row(current), rng);
  }
  /// Draws s_0 from initial().
  int sample_initial(Rng& rng) const { return detail::sample_row(initial_, rng); }

  /// Speed-model parameters (mean LOS length, mean NLOS length, dt, form); zeros for the fixed model.
  double mean_los() const { return mean_los_; }
  double mean_nlos() const { return mean_nlos_; }
  double dt() const { return dt_; }
  SpeedModel form() const { return form_; }

 private:
  enum class Kind { kFixed, kSpeed };
  /// The speed model's 2 x 2 matrix at transversal speed w: eq. (15), (17) or (18).
  Mat<2, 2> speed_matrix(double w) const {
    switch (form_) {
      case SpeedModel::kSingle: return speed_transition_single(w, dt_, mean_los_, mean_nlos_);
      case SpeedModel::kMemoryless:  // eq. (18) does not depend on w, but w is checked as for (15), (17)
        nlosloc::detail::ensure_nonnegative(w, "w");
        return Q_;
      default: return speed_transition_multiple(w, dt_, mean_los_, mean_nlos_);
    }
  }
  void set_initial(const VecX& initial) {
    if (initial.size() == 0) {
      initial_ = detail::stationary_distribution(Q_);
      return;
    }
    nlosloc::detail::ensure_shape(initial, Q_.rows(), 1, "initial");
    nlosloc::detail::ensure_finite(initial, "initial");
    NLOSLOC_ENSURE((initial.array() >= 0.0).all() && std::abs(initial.sum() - 1.0) < 1e-9,
                   "initial: expected non-negative probabilities summing to 1");
    initial_ = initial;
  }
  Kind kind_ = Kind::kFixed;
  MatX Q_ = MatX::Identity(1, 1);
  VecX initial_ = VecX::Ones(1);
  long k_sight_ = 1;
  double mean_los_ = 0.0, mean_nlos_ = 0.0, dt_ = 0.0;
  SpeedModel form_ = SpeedModel::kMultiple;
};

/// Probability that a speed-dependent two-state chain leaves condition `current` in one interval at
/// transversal speed w, in closed form (no checks; for the particle filter's inner loop). With a = w dt:
/// eq. (15): a / (a + L_cur); eq. (17): p_LN p_NN rho = a L_N / (a (L_L + L_N) + L_L L_N) from LOS and
/// a L_L / (same) from NLOS; eq. (18): the other condition's stationary probability.
inline double speed_switch_probability(const SightModel& m, int current, double w) {
  const double a = w * m.dt(), ll = m.mean_los(), ln = m.mean_nlos();
  switch (m.form()) {
    case SpeedModel::kSingle: return a / (a + (current == 0 ? ll : ln));
    case SpeedModel::kMemoryless: return (current == 0 ? ln : ll) / (ll + ln);
    default: return a * (current == 0 ? ln : ll) / (a * (ll + ln) + ll * ln);
  }
}

/// Sight process of B anchors: one independent SightModel each (Huerta eq. 9). All share N_z.
class SightProcess {
 public:
  SightProcess() = default;
  /// One model per anchor (B >= 1, same N_z for all).
  explicit SightProcess(std::vector<SightModel> models) : models_(std::move(models)) {
    NLOSLOC_ENSURE(!models_.empty(), "models: expected at least one anchor");
    for (const auto& m : models_)
      NLOSLOC_ENSURE(m.num_conditions() == models_.front().num_conditions(),
                     "models: every anchor must have the same number of conditions N_z");
  }
  /// The same model for `num_anchors` anchors.
  SightProcess(const SightModel& model, int num_anchors)
      : SightProcess(std::vector<SightModel>(checked_anchors(num_anchors), model)) {}

  int num_anchors() const { return static_cast<int>(models_.size()); }
  int num_conditions() const { return models_.empty() ? 0 : models_.front().num_conditions(); }
  const SightModel& model(int b) const {
    if (b < 0 || b >= num_anchors())  // std::out_of_range (IndexError in Python), naming the argument
      throw std::out_of_range("b: expected an anchor index in [0, " + std::to_string(num_anchors()) +
                              "), got " + std::to_string(b));
    return models_[static_cast<std::size_t>(b)];
  }
  /// True when any anchor's matrix depends on the transversal speed (filters then need the state).
  bool speed_dependent() const {
    for (const auto& m : models_)
      if (m.speed_dependent()) return true;
    return false;
  }

  /// Draws the initial situation vector (size B).
  VecXi sample_initial(Rng& rng) const {
    VecXi s(num_anchors());
    for (int b = 0; b < num_anchors(); ++b) s(b) = models_[static_cast<std::size_t>(b)].sample_initial(rng);
    return s;
  }
  /// Draws s_k from s_{k-1} = `current` anchor by anchor (eq. 9); `speeds` are the transversal speeds per
  /// anchor (size B; may be empty when no model is speed-dependent, and checked whenever given).
  VecXi sample_next(const VecXi& current, long k, const VecX& speeds, Rng& rng) const {
    nlosloc::detail::ensure_shape(current, num_anchors(), 1, "current");
    const bool need = checked_speeds(speeds);
    VecXi s(num_anchors());
    for (int b = 0; b < num_anchors(); ++b)
      s(b) = models_[static_cast<std::size_t>(b)].sample_next(current(b), k, need ? speeds(b) : 0.0, rng);
    return s;
  }

  /// log p(s_k = to | s_{k-1} = from) = sum_b log T_b(from_b, to_b) (Huerta eq. 9).
  double log_transition(const VecXi& from, const VecXi& to, long k, const VecX& speeds) const {
    nlosloc::detail::ensure_shape(from, num_anchors(), 1, "from");
    nlosloc::detail::ensure_shape(to, num_anchors(), 1, "to");
    const bool need = checked_speeds(speeds);
    double l = 0.0;
    MatX T;
    for (int b = 0; b < num_anchors(); ++b) {
      models_[static_cast<std::size_t>(b)].transition(k, need ? speeds(b) : 0.0, T);
      NLOSLOC_ENSURE(from(b) >= 0 && from(b) < T.rows() && to(b) >= 0 && to(b) < T.rows(),
                     "from/to: condition out of range [0, N_z)");
      l += std::log(T(from(b), to(b)));
    }
    return l;
  }

 private:
  /// speeds: B transversal speeds, finite and >= 0 (named here, not as the chain's internal w); empty is
  /// allowed when no chain is speed-dependent. Returns whether the chains read them.
  bool checked_speeds(const VecX& speeds) const {
    const bool need = speed_dependent();
    if (!need && speeds.size() == 0) return false;
    nlosloc::detail::ensure_shape(speeds, num_anchors(), 1, "speeds");
    for (Eigen::Index b = 0; b < speeds.size(); ++b)
      NLOSLOC_ENSURE(std::isfinite(speeds[b]) && speeds[b] >= 0.0,
                     "speeds: expected finite transversal speeds >= 0, got " + std::to_string(speeds[b]) +
                         " at anchor " + std::to_string(b));
    return need;
  }

  static std::size_t checked_anchors(int num_anchors) {
    NLOSLOC_ENSURE(num_anchors >= 1,
                   "num_anchors: expected an integer >= 1, got " + std::to_string(num_anchors));
    return static_cast<std::size_t>(num_anchors);
  }

  std::vector<SightModel> models_;
};

}  // namespace nlosloc::situation
