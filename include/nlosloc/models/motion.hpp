#pragma once
/// \file motion.hpp
/// Linear motion models x_t = F x_{t-1} + w_t, w_t ~ N(0, Q). Each model declares its state size kDim
/// and a StateLayout that tells measurement models where position, velocity and the clock sit.
#include <string>

#include "nlosloc/core/types.hpp"

namespace nlosloc {

/// Where the pieces of a state vector are; -1 marks an absent piece.
struct StateLayout {
  int dim = 0;           ///< total state size
  int space_dim = 2;     ///< 2-D or 3-D position
  int position = 0;      ///< index of the first position coordinate
  int velocity = -1;     ///< index of the first velocity coordinate
  int clock_bias = -1;   ///< RTOA clock bias tau in light-metres (Huerta eq. 5)
  int clock_drift = -1;  ///< its rate, lm/s
  int skew = -1;         ///< two-way-ranging clock skew omega (Grisales eq. 12)
  int offset = -1;       ///< two-way-ranging clock offset phi, s (Grisales eq. 12)
};

/// Process-noise form of the constant-velocity model.
enum class VelocityNoise {
  kRandomWalk = 0,        ///< Huerta eqs. (6)-(7): Q = [[0, 0], [0, dt sigma^2 I]] (velocity random walk)
  kWhiteAcceleration = 1  ///< Ke and Wu eq. (16): Q = G G^T sigma^2, G = [dt^2/2 I; dt I]
};

namespace detail {
inline void check_dt(double dt) { ensure_positive(dt, "dt"); }
/// F and Q of a motion model built from finite parameters can still overflow (sigma2 = 1e308, or dt^4
/// sigma2 in Ke and Wu's white-acceleration Q): refused here, naming the parameters, rather than met as inf
/// in the first predicted covariance.
template <class M>
void check_model_finite(const M& F, const M& Q, const char* params) {
  NLOSLOC_ENSURE(F.allFinite() && Q.allFinite(),
                 std::string(params) +
                     ": the transition F or process noise Q overflows; expected parameters "
                     "giving finite matrices");
}
}  // namespace detail

/// Constant velocity in D = 2 or 3 dimensions, state [p (D), v (D)].
template <int D>
class ConstantVelocity {
  static_assert(D == 2 || D == 3, "ConstantVelocity: D must be 2 or 3");

 public:
  static constexpr int kDim = 2 * D;
  using State = Vec<kDim>;
  using Matrix = Mat<kDim, kDim>;

  /// dt > 0 (s); sigma2 >= 0: velocity random-walk variance rate ((m/s)^2/s, Huerta sigma_v^2) or
  /// acceleration variance ((m/s^2)^2, Ke and Wu), depending on `noise`.
  ConstantVelocity(double dt, double sigma2, VelocityNoise noise = VelocityNoise::kRandomWalk)
      : dt_(dt), sigma2_(sigma2), noise_(noise) {
    detail::check_dt(dt);
    detail::ensure_nonnegative(sigma2, "sigma2");
    NLOSLOC_ENSURE(noise == VelocityNoise::kRandomWalk || noise == VelocityNoise::kWhiteAcceleration,
                   "noise: expected VelocityNoise.RandomWalk or VelocityNoise.WhiteAcceleration");
    const auto I = Mat<D, D>::Identity();
    F_.setIdentity();
    F_.template topRightCorner<D, D>() = dt * I;  // Huerta eq. (7)
    Q_.setZero();
    if (noise == VelocityNoise::kRandomWalk) {
      Q_.template bottomRightCorner<D, D>() = dt * sigma2 * I;  // Huerta eq. (6)
    } else {
      // Ke and Wu eq. (16): w = G a, a ~ N(0, sigma2 I), G = [dt^2/2 I; dt I].
      Q_.template topLeftCorner<D, D>() = 0.25 * dt * dt * dt * dt * sigma2 * I;
      Q_.template topRightCorner<D, D>() = 0.5 * dt * dt * dt * sigma2 * I;
      Q_.template bottomLeftCorner<D, D>() = 0.5 * dt * dt * dt * sigma2 * I;
      Q_.template bottomRightCorner<D, D>() = dt * dt * sigma2 * I;
    }
    detail::check_model_finite(F_, Q_, "dt, sigma2");
  }

  double dt() const { return dt_; }
  double sigma2() const { return sigma2_; }
  VelocityNoise noise() const { return noise_; }
  const Matrix& F() const { return F_; }
  const Matrix& Q() const { return Q_; }
  static StateLayout layout() { return {kDim, D, 0, D, -1, -1, -1, -1}; }

 private:
  double dt_, sigma2_;
  VelocityNoise noise_;
  Matrix F_, Q_;
};

/// Constant velocity plus clock bias and drift (unsynchronised mobile), state [p (D), tau, v (D), tau_dot]
/// with tau in light-metres (Huerta eq. 5); Q of eq. (6), F of eq. (7) on [p, tau] and their rates.
template <int D>
class ConstantVelocityClock {
  static_assert(D == 2 || D == 3, "ConstantVelocityClock: D must be 2 or 3");

 public:
  static constexpr int kDim = 2 * (D + 1);
  using State = Vec<kDim>;
  using Matrix = Mat<kDim, kDim>;

  /// dt > 0 (s); sigma_v2 >= 0 ((m/s)^2/s); sigma_tau2 >= 0 ((lm/s)^2/s).
  ConstantVelocityClock(double dt, double sigma_v2, double sigma_tau2)
      : dt_(dt), sigma_v2_(sigma_v2), sigma_tau2_(sigma_tau2) {
    detail::check_dt(dt);
    detail::ensure_nonnegative(sigma_v2, "sigma_v2");
    detail::ensure_nonnegative(sigma_tau2, "sigma_tau2");
    constexpr int H = D + 1;
    F_.setIdentity();
    F_.template topRightCorner<H, H>() = dt * Mat<H, H>::Identity();  // Huerta eq. (7)
    Q_.setZero();
    for (int i = 0; i < D; ++i) Q_(H + i, H + i) = dt * sigma_v2;  // Huerta eq. (6), unsynchronised MT
    Q_(kDim - 1, kDim - 1) = dt * sigma_tau2;
    detail::check_model_finite(F_, Q_, "dt, sigma_v2, sigma_tau2");
  }

  double dt() const { return dt_; }
  double sigma_v2() const { return sigma_v2_; }
  double sigma_tau2() const { return sigma_tau2_; }
  const Matrix& F() const { return F_; }
  const Matrix& Q() const { return Q_; }
  static StateLayout layout() { return {kDim, D, 0, D + 1, D, 2 * D + 1, -1, -1}; }

 private:
  double dt_, sigma_v2_, sigma_tau2_;
  Matrix F_, Q_;
};

/// Two-way-ranging clock and mobility model of Grisales and Fierens, eqs. (14)-(15):
/// state s = (omega, phi, vx, vy, x, y) (skew, offset in s, velocity m/s, position m).
class TwoWayClock {
 public:
  static constexpr int kDim = 6;
  using State = Vec<kDim>;
  using Matrix = Mat<kDim, kDim>;

  /// h > 0: observation period (s); standard deviations >= 0 of the skew, offset (s) and velocity (m/s)
  /// steps (R^u = diag(sigma_omega^2, sigma_phi^2, sigma_v^2, sigma_v^2)).
  TwoWayClock(double h, double sigma_omega, double sigma_phi, double sigma_v)
      : h_(h), sigma_omega_(sigma_omega), sigma_phi_(sigma_phi), sigma_v_(sigma_v) {
    detail::ensure_positive(h, "h");
    detail::ensure_nonnegative(sigma_omega, "sigma_omega");
    detail::ensure_nonnegative(sigma_phi, "sigma_phi");
    detail::ensure_nonnegative(sigma_v, "sigma_v");
    F_.setIdentity();
    F_(4, 2) = h;  // Grisales eq. (15)
    F_(5, 3) = h;
    Q_.setZero();  // Q = G R^u G^T with G = [I4; 0] (eq. 15)
    Q_(0, 0) = sigma_omega * sigma_omega;
    Q_(1, 1) = sigma_phi * sigma_phi;
    Q_(2, 2) = Q_(3, 3) = sigma_v * sigma_v;
    detail::check_model_finite(F_, Q_, "dt, sigma_omega, sigma_phi, sigma_v");
  }

  double dt() const { return h_; }
  double sigma_omega() const { return sigma_omega_; }
  double sigma_phi() const { return sigma_phi_; }
  double sigma_v() const { return sigma_v_; }
  const Matrix& F() const { return F_; }
  const Matrix& Q() const { return Q_; }
  static StateLayout layout() { return {kDim, 2, 4, 2, -1, -1, 0, 1}; }

 private:
  double h_, sigma_omega_, sigma_phi_, sigma_v_;
  Matrix F_, Q_;
};

using ConstantVelocity2 = ConstantVelocity<2>;
using ConstantVelocity3 = ConstantVelocity<3>;
using ConstantVelocityClock2 = ConstantVelocityClock<2>;
using ConstantVelocityClock3 = ConstantVelocityClock<3>;

}  // namespace nlosloc
