#pragma once
/// \file measurement.hpp
/// A stack of measurement rows y = g(x) + n(s), each row tied to the anchor b(i) whose sight condition
/// s selects the row's noise distribution. Row types follow Huerta et al. 2009 Table I (TOA, RTOA, TDOA,
/// AOA as geometric angle or array phase) and Grisales and Fierens eqs. (17)-(20) (two-way ranging pair).
///
/// The stack is built once (allocation happens in the add_* calls); the evaluation functions write into
/// caller-provided buffers and never allocate, so filters can call them per sigma point.
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nlosloc/core/types.hpp"
#include "nlosloc/models/motion.hpp"
#include "nlosloc/models/noise.hpp"

namespace nlosloc {

/// Kind of one measurement row.
enum class RowKind {
  kToa = 0,       ///< ||p - q_i||, Huerta Table I
  kRtoa = 1,      ///< ||p - q_i|| + tau, Huerta Table I (tau in light-metres)
  kTdoa = 2,      ///< ||p - q_i1|| - ||p - q_i2||, Huerta Table I (uncorrelated TDOA)
  kAoa = 3,       ///< bearing of the mobile seen from the anchor, atan2(p - q), rad, wrapped
  kAoaPhase = 4,  ///< electric phase pi sin(theta - theta_sector) of a half-wavelength ULA (scenario H1)
  kTwrTau = 5,    ///< two-way ranging reception time tau, Grisales eq. (17), s
  kTwrT = 6,      ///< two-way ranging half round trip T, Grisales eq. (20), s
  kLinear = 7     ///< h^T x, for linear-Gaussian checks (e.g. KF against UKF)
};

const char* to_string(RowKind k);

/// Per-row description (read-only view for users; the stack owns it).
struct MeasurementRow {
  RowKind kind = RowKind::kToa;
  int anchor = -1;   ///< anchor b(i) whose sight selects the noise (-1: always condition 0)
  int anchor2 = -1;  ///< second anchor of a TDOA row, else -1
  int input = 0;     ///< first augmented noise input of this row
  int inputs = 1;    ///< number of augmented noise inputs it owns (TDOA 2, TWR pair 5 on the tau row)
  double sector_center = 0.0;  ///< AoaPhase: broadside direction of the serving array, rad
  int slot = 0;                ///< TWR: exchange slot i of the anchor (message sent at t_k + i Delta)
  int linear = -1;             ///< Linear: index into the stored coefficient rows
};

/// Stack of measurement rows over a state described by a StateLayout.
class MeasurementStack {
 public:
  using Dist = noise::Distribution;

  /// `layout`: where position/clock sit in the state (take it from the motion model);
  /// `anchors`: B x D anchor positions (D = layout.space_dim), finite;
  /// `num_conditions` >= 1: sight conditions per anchor (LOS = 0 plus NLOS types).
  MeasurementStack(const StateLayout& layout, const MatX& anchors, int num_conditions = 2)
      : layout_(layout), anchors_(anchors), num_conditions_(num_conditions) {
    check_layout(layout);
    detail::ensure_shape(anchors, -1, layout.space_dim, "anchors");
    detail::ensure_finite(anchors, "anchors");
    NLOSLOC_ENSURE(num_conditions >= 1,
                   "num_conditions: expected >= 1, got " + std::to_string(num_conditions));
  }

  // ---- building -------------------------------------------------------------------------------
  /// TOA row of `anchor` with one noise distribution per sight condition (Huerta Table I).
  MeasurementStack& add_toa(int anchor, const std::vector<Dist>& noise) {
    return add_simple(RowKind::kToa, anchor, noise, "add_toa");
  }
  /// RTOA (pseudorange) row: needs a clock_bias in the layout (Huerta eq. 5 and Table I).
  MeasurementStack& add_rtoa(int anchor, const std::vector<Dist>& noise) {
    NLOSLOC_ENSURE(layout_.clock_bias >= 0,
                   "add_rtoa: the state layout has no clock bias (use ConstantVelocityClock)");
    return add_simple(RowKind::kRtoa, anchor, noise, "add_rtoa");
  }
  /// Geometric AOA row (bearing of the mobile from the anchor in the x-y plane, rad).
  MeasurementStack& add_aoa(int anchor, const std::vector<Dist>& noise) {
    return add_simple(RowKind::kAoa, anchor, noise, "add_aoa");
  }
  /// AOA as the phase psi = pi sin(theta - sector_center) of a half-wavelength ULA whose broadside
  /// points at sector_center (scenario H1 choice of reference/scenarios.md).
  MeasurementStack& add_aoa_phase(int anchor, double sector_center, const std::vector<Dist>& noise) {
    NLOSLOC_ENSURE(std::isfinite(sector_center), "sector_center: expected a finite angle (rad)");
    add_simple(RowKind::kAoaPhase, anchor, noise, "add_aoa_phase");
    rows_.back().sector_center = sector_center;
    return *this;
  }
  /// TDOA row ||p - q_a|| - ||p - q_b||; its noise is n_a - n_b with each anchor's own distributions.
  MeasurementStack& add_tdoa(int anchor_a, int anchor_b, const std::vector<Dist>& noise_a,
                             const std::vector<Dist>& noise_b) {
    check_anchor(anchor_a, "add_tdoa: anchor_a");
    check_anchor(anchor_b, "add_tdoa: anchor_b");
    NLOSLOC_ENSURE(anchor_a != anchor_b, "add_tdoa: anchor_a and anchor_b must differ");
    check_noise(noise_a, "add_tdoa: noise_a");
    check_noise(noise_b, "add_tdoa: noise_b");
    MeasurementRow r;
    r.kind = RowKind::kTdoa;
    r.anchor = anchor_a;
    r.anchor2 = anchor_b;
    r.input = noise_dim_;
    r.inputs = 2;
    push(r, noise_a, noise_b);
    return *this;
  }
  /// Two-way-ranging pair (tau, T) with anchor `anchor` in exchange slot `slot` (Grisales eqs. 17-20):
  /// needs skew/offset in the layout. `delta_slot` = Delta, `reply_delay` = delta (s), `sigma_m` >= 0 the
  /// time-stamping noise std (s); `gamma[z]` the NLOS delay distribution of condition z (nullopt = 0, LOS).
  MeasurementStack& add_twr(int anchor, int slot, double delta_slot, double reply_delay, double sigma_m,
                            const std::vector<std::optional<Dist>>& gamma) {
    NLOSLOC_ENSURE(layout_.skew >= 0 && layout_.offset >= 0,
                   "add_twr: the state layout has no clock skew/offset (use TwoWayClock)");
    check_anchor(anchor, "add_twr: anchor");
    NLOSLOC_ENSURE(slot >= 0, "add_twr: slot: expected >= 0");
    detail::ensure_nonnegative(delta_slot, "add_twr: delta_slot");
    detail::ensure_nonnegative(reply_delay, "add_twr: reply_delay");
    detail::ensure_positive(sigma_m, "add_twr: sigma_m");
    NLOSLOC_ENSURE(static_cast<int>(gamma.size()) == num_conditions_,
                   "add_twr: gamma: expected one entry per sight condition (" +
                       std::to_string(num_conditions_) + "), got " + std::to_string(gamma.size()));
    MeasurementRow r;
    r.kind = RowKind::kTwrTau;
    r.anchor = anchor;
    r.slot = slot;
    r.input = noise_dim_;
    r.inputs = 5;  // n^A, n^B, n^C, n^D, Gamma (Grisales eq. 28 and 27)
    twr_.push_back({delta_slot, reply_delay, sigma_m, gamma});
    r.linear = static_cast<int>(twr_.size()) - 1;
    push(r, {}, {});
    MeasurementRow r2 = r;
    r2.kind = RowKind::kTwrT;
    r2.input = noise_dim_;
    r2.inputs = 0;  // shares the inputs of the tau row
    push(r2, {}, {});
    return *this;
  }
  /// Linear row y = h^T x + n (h of the state size); `anchor` may be -1 (condition 0 always).
  MeasurementStack& add_linear(const VecX& h, int anchor, const std::vector<Dist>& noise) {
    detail::ensure_shape(h, layout_.dim, 1, "add_linear: h");
    detail::ensure_finite(h, "add_linear: h");
    if (anchor != -1) check_anchor(anchor, "add_linear: anchor");
    check_noise(noise, "add_linear: noise");
    MeasurementRow r;
    r.kind = RowKind::kLinear;
    r.anchor = anchor;
    r.input = noise_dim_;
    lin_.push_back(h);
    r.linear = static_cast<int>(lin_.size()) - 1;
    push(r, noise, {});
    return *this;
  }

  // ---- queries ----------------------------------------------------------------------------------
  int rows() const { return static_cast<int>(rows_.size()); }
  int noise_dim() const { return noise_dim_; }
  /// Calls f(k) for each augmented noise input k that row i's value reads in predict_augmented: a TWR
  /// pair's tau row (eq. 17) reads n^A, n^B and Gamma of the pair's five, its T row (eq. 20) all five.
  template <class F>
  void for_each_input(int i, F&& f) const {
    const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
    if (r.kind == RowKind::kTwrTau) {
      for (const int k : {0, 1, 4}) f(r.input + k);
    } else if (r.kind == RowKind::kTwrT) {
      const int first = rows_[static_cast<std::size_t>(i) - 1].input;  // the tau row's inputs
      for (int k = 0; k < 5; ++k) f(first + k);
    } else {
      for (int k = 0; k < r.inputs; ++k) f(r.input + k);
    }
  }
  int num_anchors() const { return static_cast<int>(anchors_.rows()); }
  int num_conditions() const { return num_conditions_; }
  const StateLayout& layout() const { return layout_; }
  const MatX& anchors() const { return anchors_; }
  const MeasurementRow& row(int i) const {
    check_row(i, "i");
    return rows_[static_cast<std::size_t>(i)];
  }
  bool is_angle(int i) const {
    check_row(i, "i");
    return angle_row(i);
  }
  bool has_angles() const { return has_angles_; }
  /// Noise distribution of row i (first anchor for TDOA) under sight condition `condition`. A two-way-ranging
  /// row has none (its noise is twr_params'): std::invalid_argument.
  const Dist& noise(int i, int condition) const { return row_noise(noise_, i, condition, "noise"); }
  /// Noise of the second anchor (n_b of n_a - n_b) of TDOA row i under `condition`.
  const Dist& noise_b(int i, int condition) const {
    check_row(i, "i");
    NLOSLOC_ENSURE(rows_[static_cast<std::size_t>(i)].kind == RowKind::kTdoa,
                   "i: row " + std::to_string(i) + " is not a TDOA row (only TDOA rows have a second noise)");
    return row_noise(noise2_, i, condition, "noise_b");
  }

  /// Parameters of a two-way-ranging pair (add_twr).
  struct TwrParams {
    double delta_slot, reply_delay, sigma_m;
    std::vector<std::optional<Dist>> gamma;  ///< NLOS delay per condition (nullopt: none)
  };
  /// The parameters of two-way-ranging row i (either row of its pair).
  const TwrParams& twr_params(int i) const {
    check_row(i, "i");
    const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
    NLOSLOC_ENSURE(r.kind == RowKind::kTwrTau || r.kind == RowKind::kTwrT,
                   "i: row " + std::to_string(i) + " is not a two-way-ranging row");
    return twr_[static_cast<std::size_t>(r.linear)];
  }
  /// h of linear row i (y = h^T x + n).
  const VecX& linear_h(int i) const {
    check_row(i, "i");
    const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
    NLOSLOC_ENSURE(r.kind == RowKind::kLinear, "i: row " + std::to_string(i) + " is not a linear row");
    return lin_[static_cast<std::size_t>(r.linear)];
  }

  /// Throws unless `sight` has one entry per anchor with values in [0, num_conditions).
  void check_sight(const VecXi& sight, const char* name = "sight") const {
    detail::ensure_shape(sight, num_anchors(), 1, name);
    for (Eigen::Index b = 0; b < sight.size(); ++b)
      NLOSLOC_ENSURE(sight[b] >= 0 && sight[b] < num_conditions_,
                     std::string(name) + ": expected conditions in [0, " + std::to_string(num_conditions_) +
                         "), got " + std::to_string(sight[b]) + " at anchor " + std::to_string(b));
  }
  /// Throws unless the stack has rows.
  void check_ready() const { NLOSLOC_ENSURE(rows() > 0, "measurements: the stack has no rows"); }

  /// Throws std::invalid_argument, naming the row, the condition and the distribution, unless every noise
  /// distribution (and two-way-ranging NLOS delay) has a finite mean and variance: the additive-noise
  /// filters (Ekf, Ukf, Iukf, the RBPF's additive bank) use only these moments, so a Gev with
  /// shape >= 0.5 (infinite variance) used to fail later as a covariance that is not positive definite, or
  /// as NaN (0 * inf in the IUKF). `who` names the caller; the augmented forms use quantiles and take them.
  void check_finite_moments(const char* who) const {
    const auto check = [&](const Dist& d, int i, int z, const char* which) {
      if (std::isfinite(d.mean()) && std::isfinite(d.variance())) return;
      detail::throw_invalid_argument(
          std::string("measurements: row ") + std::to_string(i) + ", condition " + std::to_string(z) + ": " +
          which + " " + d.name() + " has mean " + std::to_string(d.mean()) + " and variance " +
          std::to_string(d.variance()) + "; " + who +
          " uses the noise moments, which must be finite (an augmented form, UkfAugmented or "
          "NoiseForm::kAugmented, uses quantiles instead)");
    };
    for (int i = 0; i < rows(); ++i) {
      const auto ui = static_cast<std::size_t>(i);
      const MeasurementRow& r = rows_[ui];
      if (r.kind == RowKind::kTwrT) continue;  // its noise is its tau row's
      for (int z = 0; z < num_conditions_; ++z) {
        const auto uz = static_cast<std::size_t>(z);
        if (r.kind == RowKind::kTwrTau) {
          const auto& g = twr_[static_cast<std::size_t>(r.linear)].gamma[uz];
          if (g) check(*g, i, z, "the NLOS delay");
          continue;
        }
        if (uz < noise_[ui].size()) check(noise_[ui][uz], i, z, "the noise");
        if (r.kind == RowKind::kTdoa) check(noise2_[ui][uz], i, z, "the noise of the second anchor");
      }
    }
  }

  // ---- evaluation (no allocation) ----------------------------------------------------------------
  /// Noise-free prediction g(x) at time t (t only matters for two-way ranging, eq. 17).
  template <class DX, class DY>
  void predict(const Eigen::MatrixBase<DX>& x, double t, Eigen::MatrixBase<DY>& y) const {
    for (int i = 0; i < rows(); ++i) y[i] = g_row(x, t, i);
  }

  /// g at every column of X (state x K) into the columns of Z (rows x K), row by row so range rows are
  /// evaluated for all points at once (the sigma-point hot path of the UKF).
  template <class DX, class DZ>
  void predict_columns(const Eigen::MatrixBase<DX>& X, double t, Eigen::MatrixBase<DZ>& Z) const {
    const int P = layout_.position;
    const Eigen::Index K = X.cols();
    for (int i = 0; i < rows(); ++i) {
      const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
      if (r.kind == RowKind::kToa || r.kind == RowKind::kRtoa) {  // ||p - q|| (+ tau), Table I
        auto zi = Z.row(i);
        zi = (X.row(P).array() - anchors_(r.anchor, 0)).square() +
             (X.row(P + 1).array() - anchors_(r.anchor, 1)).square();
        if (layout_.space_dim == 3) zi.array() += (X.row(P + 2).array() - anchors_(r.anchor, 2)).square();
        zi = zi.array().sqrt();
        if (r.kind == RowKind::kRtoa) zi += X.row(layout_.clock_bias);
      } else {
        for (Eigen::Index j = 0; j < K; ++j) Z(i, j) = g_row(X.col(j), t, i);
      }
    }
  }

  /// Analytic Jacobian dg/dx (rows x state); J must be pre-sized.
  template <class DX, class DJ>
  void jacobian(const Eigen::MatrixBase<DX>& x, double t, Eigen::MatrixBase<DJ>& J) const {
    J.setZero();
    const int P = layout_.position, Dm = layout_.space_dim;
    for (int i = 0; i < rows(); ++i) {
      const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
      switch (r.kind) {
        case RowKind::kToa:
        case RowKind::kRtoa:
          J.row(i).segment(P, Dm) = unit(x, r.anchor).transpose();  // d||p-q||/dp
          if (r.kind == RowKind::kRtoa) J(i, layout_.clock_bias) = 1.0;
          break;
        case RowKind::kTdoa:
          J.row(i).segment(P, Dm) = (unit(x, r.anchor) - unit(x, r.anchor2)).transpose();
          break;
        case RowKind::kAoa:
        case RowKind::kAoaPhase: {
          const double dx = x[P] - anchors_(r.anchor, 0), dy = x[P + 1] - anchors_(r.anchor, 1);
          const double d2 = dx * dx + dy * dy;
          double scale = d2 > 0.0 ? 1.0 / d2 : 0.0;  // d atan2(dy, dx) = (-dy, dx)/d^2
          if (r.kind == RowKind::kAoaPhase)
            scale *= kPi * std::cos(std::atan2(dy, dx) - r.sector_center);  // chain rule of pi sin(.)
          J(i, P) = -dy * scale;
          J(i, P + 1) = dx * scale;
          break;
        }
        case RowKind::kTwrTau: {
          const TwrParams& w = twr_[static_cast<std::size_t>(r.linear)];
          const double om = x[layout_.skew];
          const double d = dist(x, r.anchor);
          J(i, layout_.skew) = t + r.slot * w.delta_slot + d / kSpeedOfLight;  // d tau / d omega, eq. (17)
          J(i, layout_.offset) = 1.0;
          J.row(i).segment(P, Dm) = (om / kSpeedOfLight) * unit(x, r.anchor).transpose();
          break;
        }
        case RowKind::kTwrT: {
          const TwrParams& w = twr_[static_cast<std::size_t>(r.linear)];
          const double om = x[layout_.skew];
          J(i, layout_.skew) = -0.5 * w.reply_delay / (om * om);  // d/d omega of delta/2 (1/omega - 1)
          J.row(i).segment(P, Dm) = unit(x, r.anchor).transpose() / kSpeedOfLight;  // eq. (20)
          break;
        }
        case RowKind::kLinear: J.row(i) = lin_[static_cast<std::size_t>(r.linear)].transpose(); break;
      }
    }
  }

  /// Mean and covariance of the noise n of y = g(x) + n under `sight`, for the additive-noise filters.
  /// Exact for every row except two-way ranging, whose noise depends on the skew: its moments are taken
  /// at the given x (Grisales eqs. 17, 20 are linear in the noises for fixed omega).
  template <class DX, class DM, class DC>
  void noise_moments(const Eigen::MatrixBase<DX>& x, const VecXi& sight, Eigen::MatrixBase<DM>& mean,
                     Eigen::MatrixBase<DC>& cov) const {
    cov.setZero();
    for (int i = 0; i < rows(); ++i) {
      const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
      const auto ui = static_cast<std::size_t>(i);
      switch (r.kind) {
        case RowKind::kTdoa: {
          const Dist& a = noise_[ui][static_cast<std::size_t>(sight[r.anchor])];
          const Dist& b = noise2_[ui][static_cast<std::size_t>(sight[r.anchor2])];
          mean[i] = a.mean() - b.mean();  // n = n_a - n_b, independent
          cov(i, i) = a.variance() + b.variance();
          break;
        }
        case RowKind::kTwrTau: {
          const TwrParams& w = twr_[static_cast<std::size_t>(r.linear)];
          const double om = x[layout_.skew], s2 = w.sigma_m * w.sigma_m;
          const auto& g = w.gamma[static_cast<std::size_t>(sight[r.anchor])];
          const double mg = g ? g->mean() : 0.0, vg = g ? g->variance() : 0.0;
          // tau noise = omega (n^A + Gamma) + n^B (eq. 17); T noise = Gamma + n^A + n^D + (n^B + n^C)/omega
          // (eq. 20): moments for fixed omega.
          mean[i] = om * mg;
          mean[i + 1] = mg;
          cov(i, i) = om * om * (s2 + vg) + s2;
          cov(i + 1, i + 1) = vg + 2.0 * s2 + 2.0 * s2 / (om * om);
          cov(i, i + 1) = cov(i + 1, i) = om * (s2 + vg) + s2 / om;
          break;
        }
        case RowKind::kTwrT: break;  // filled with its tau row
        default: {
          const Dist& a = noise_[ui][static_cast<std::size_t>(r.anchor < 0 ? 0 : sight[r.anchor])];
          mean[i] = a.mean();
          cov(i, i) = a.variance();
        }
      }
    }
  }

  /// y = g(x) + n with the noise built from standard-normal inputs u (size noise_dim()) through each
  /// distribution's quantile map (Huerta Sec. V-A, Grisales eq. 29): the augmented sigma-point form.
  template <class DX, class DU, class DY>
  void predict_augmented(const Eigen::MatrixBase<DX>& x, double t, const Eigen::MatrixBase<DU>& u,
                         const VecXi& sight, Eigen::MatrixBase<DY>& y) const {
    for (int i = 0; i < rows(); ++i) {
      const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
      const auto ui = static_cast<std::size_t>(i);
      switch (r.kind) {
        case RowKind::kTdoa:
          y[i] = g_row(x, t, i) +
                 noise_[ui][static_cast<std::size_t>(sight[r.anchor])].from_standard_normal(u[r.input]) -
                 noise2_[ui][static_cast<std::size_t>(sight[r.anchor2])].from_standard_normal(u[r.input + 1]);
          break;
        case RowKind::kTwrTau: {
          const TwrParams& w = twr_[static_cast<std::size_t>(r.linear)];
          const double om = x[layout_.skew], phi = x[layout_.offset];
          const double nA = w.sigma_m * u[r.input], nB = w.sigma_m * u[r.input + 1];
          const double nC = w.sigma_m * u[r.input + 2], nD = w.sigma_m * u[r.input + 3];
          const auto& g = w.gamma[static_cast<std::size_t>(sight[r.anchor])];
          const double G = g ? g->from_standard_normal(u[r.input + 4]) : 0.0;
          const double dc = dist(x, r.anchor) / kSpeedOfLight;
          y[i] = om * (t + r.slot * w.delta_slot + nA + dc + G) + phi + nB;                       // eq. (17)
          y[i + 1] = dc + G + 0.5 * w.reply_delay * (1.0 / om - 1.0) + nA + nD + (nB + nC) / om;  // eq. (20)
          break;
        }
        case RowKind::kTwrT: break;
        default:
          y[i] =
              g_row(x, t, i) +
              noise_[ui][static_cast<std::size_t>(r.anchor < 0 ? 0 : sight[r.anchor])].from_standard_normal(
                  u[r.input]);
      }
    }
  }

  /// In-place residual a - b with angle rows wrapped to (-pi, pi].
  template <class D>
  void wrap_residual(Eigen::MatrixBase<D>& r) const {
    if (!has_angles_) return;
    for (int i = 0; i < rows(); ++i)
      if (angle_row(i)) r[i] = wrap_angle(r[i]);
  }

  /// Wraps the angle rows of every column of a rows x K matrix of residuals.
  template <class D>
  void wrap_residual_cols(Eigen::MatrixBase<D>& R) const {
    if (!has_angles_) return;
    for (int i = 0; i < rows(); ++i)
      if (angle_row(i))
        for (Eigen::Index j = 0; j < R.cols(); ++j) R(i, j) = wrap_angle(R(i, j));
  }

 private:
  const Dist& row_noise(const std::vector<std::vector<Dist>>& table, int i, int condition,
                        const char* what) const {
    check_row(i, "i");
    if (condition < 0 || condition >= num_conditions_)  // std::out_of_range: IndexError in Python, as for i
      throw std::out_of_range("condition: expected a sight condition in [0, " +
                              std::to_string(num_conditions_) + "), got " + std::to_string(condition));
    const std::vector<Dist>& n = table[static_cast<std::size_t>(i)];
    NLOSLOC_ENSURE(!n.empty(), std::string(what) + ": row " + std::to_string(i) +
                                   " is a two-way-ranging row; its noise is in twr_params(i)");
    return n[static_cast<std::size_t>(condition)];
  }

  /// Throws unless the layout's indices fit its state: the position (and velocity, when present) blocks
  /// of space_dim entries and each clock entry (-1 when absent) inside [0, dim). The rows read and write
  /// the state at these indices unchecked, so a bad layout would read or write out of bounds.
  static void check_layout(const StateLayout& L) {
    NLOSLOC_ENSURE(L.dim > 0 && (L.space_dim == 2 || L.space_dim == 3),
                   "layout: expected dim > 0 and space_dim 2 or 3, got dim " + std::to_string(L.dim) +
                       ", space_dim " + std::to_string(L.space_dim) + " (take it from the motion model)");
    auto block = [&](int at, int size, const char* field, bool optional) {
      NLOSLOC_ENSURE((optional && at == -1) || (at >= 0 && at + size <= L.dim),
                     std::string("layout: ") + field + " = " + std::to_string(at) +
                         " does not fit a state of " + std::to_string(L.dim) +
                         (optional ? " (-1 when absent)" : "") + " (take the layout from the motion model)");
    };
    block(L.position, L.space_dim, "position", false);
    block(L.velocity, L.space_dim, "velocity", true);
    block(L.clock_bias, 1, "clock_bias", true);
    block(L.clock_drift, 1, "clock_drift", true);
    block(L.skew, 1, "skew", true);
    block(L.offset, 1, "offset", true);
  }
  /// std::out_of_range (IndexError in Python) unless i is a row index.
  void check_row(int i, const char* name) const {
    if (i < 0 || i >= rows())
      throw std::out_of_range(std::string(name) + ": expected a row index in [0, " + std::to_string(rows()) +
                              "), got " + std::to_string(i));
  }
  /// Unchecked is_angle for the per-sigma-point loops.
  bool angle_row(int i) const {
    const RowKind k = rows_[static_cast<std::size_t>(i)].kind;
    return k == RowKind::kAoa || k == RowKind::kAoaPhase;
  }
  void check_anchor(int a, const char* name) const {
    NLOSLOC_ENSURE(a >= 0 && a < num_anchors(), std::string(name) + ": expected an anchor index in [0, " +
                                                    std::to_string(num_anchors()) + "), got " +
                                                    std::to_string(a));
  }
  void check_noise(const std::vector<Dist>& noise, const char* name) const {
    NLOSLOC_ENSURE(static_cast<int>(noise.size()) == num_conditions_,
                   std::string(name) + ": expected one distribution per sight condition (" +
                       std::to_string(num_conditions_) + "), got " + std::to_string(noise.size()));
  }
  MeasurementStack& add_simple(RowKind k, int anchor, const std::vector<Dist>& noise, const char* fn) {
    check_anchor(anchor, (std::string(fn) + ": anchor").c_str());
    check_noise(noise, (std::string(fn) + ": noise").c_str());
    if (k == RowKind::kAoa || k == RowKind::kAoaPhase) has_angles_ = true;
    MeasurementRow r;
    r.kind = k;
    r.anchor = anchor;
    r.input = noise_dim_;
    push(r, noise, {});
    return *this;
  }
  void push(const MeasurementRow& r, const std::vector<Dist>& n1, const std::vector<Dist>& n2) {
    rows_.push_back(r);
    noise_.push_back(n1);
    noise2_.push_back(n2);
    noise_dim_ += r.inputs;
  }

  template <class DX>
  double dist(const Eigen::MatrixBase<DX>& x, int a) const {
    const int P = layout_.position;
    double s = 0.0;
    for (int k = 0; k < layout_.space_dim; ++k) {
      const double d = x[P + k] - anchors_(a, k);
      s += d * d;
    }
    return std::sqrt(s);
  }
  /// (p - q_a)/||p - q_a|| as a 3-vector (last entry unused in 2-D); zero at the anchor itself.
  template <class DX>
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> unit(const Eigen::MatrixBase<DX>& x, int a) const {
    const int P = layout_.position, Dm = layout_.space_dim;
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> v(Dm);
    for (int k = 0; k < Dm; ++k) v[k] = x[P + k] - anchors_(a, k);
    const double n = v.norm();
    if (n > 0.0) v /= n;
    return v;
  }
  template <class DX>
  double g_row(const Eigen::MatrixBase<DX>& x, double t, int i) const {
    const MeasurementRow& r = rows_[static_cast<std::size_t>(i)];
    const int P = layout_.position;
    switch (r.kind) {
      case RowKind::kToa: return dist(x, r.anchor);                           // Table I
      case RowKind::kRtoa: return dist(x, r.anchor) + x[layout_.clock_bias];  // Table I
      case RowKind::kTdoa: return dist(x, r.anchor) - dist(x, r.anchor2);     // Table I
      case RowKind::kAoa: return std::atan2(x[P + 1] - anchors_(r.anchor, 1), x[P] - anchors_(r.anchor, 0));
      case RowKind::kAoaPhase:  // psi(theta) of a half-wavelength ULA, H1 choice
        return kPi * std::sin(std::atan2(x[P + 1] - anchors_(r.anchor, 1), x[P] - anchors_(r.anchor, 0)) -
                              r.sector_center);
      case RowKind::kTwrTau: {  // Grisales eq. (22), noise-free
        const TwrParams& w = twr_[static_cast<std::size_t>(r.linear)];
        return x[layout_.skew] * (t + r.slot * w.delta_slot + dist(x, r.anchor) / kSpeedOfLight) +
               x[layout_.offset];
      }
      case RowKind::kTwrT: {  // Grisales eq. (23)
        const TwrParams& w = twr_[static_cast<std::size_t>(r.linear)];
        return dist(x, r.anchor) / kSpeedOfLight + 0.5 * w.reply_delay * (1.0 / x[layout_.skew] - 1.0);
      }
      case RowKind::kLinear: return lin_[static_cast<std::size_t>(r.linear)].dot(x);
    }
    return 0.0;
  }

  StateLayout layout_;
  MatX anchors_;
  int num_conditions_;
  int noise_dim_ = 0;
  bool has_angles_ = false;
  std::vector<MeasurementRow> rows_;
  std::vector<std::vector<Dist>> noise_, noise2_;
  std::vector<TwrParams> twr_;
  std::vector<VecX> lin_;
};

inline const char* to_string(RowKind k) {
  switch (k) {
    case RowKind::kToa: return "toa";
    case RowKind::kRtoa: return "rtoa";
    case RowKind::kTdoa: return "tdoa";
    case RowKind::kAoa: return "aoa";
    case RowKind::kAoaPhase: return "aoa_phase";
    case RowKind::kTwrTau: return "twr_tau";
    case RowKind::kTwrT: return "twr_T";
    default: return "linear";
  }
}

}  // namespace nlosloc
