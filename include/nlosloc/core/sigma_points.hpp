#pragma once
/// \file sigma_points.hpp
/// Sigma-point schemes for the unscented transform. Every scheme here uses 2n+1 points
/// x0 = m, x(i) = m + gamma L(:,i), x(n+i) = m - gamma L(:,i) with L L^T = P, and differs only in
/// gamma and the weights, so one filter implementation serves all of them.
#include <cmath>
#include <string>

#include "nlosloc/core/types.hpp"

namespace nlosloc {

/// Weights of a 2n+1 point set: mean weight of the centre point, covariance weight of the centre point,
/// the common weight of the 2n outer points (mean and covariance), and the spread gamma.
struct SigmaWeights {
  double gamma = 1.0;
  double wm0 = 0.0;
  double wc0 = 0.0;
  double wi = 0.0;
};

/// Which sigma-point rule to use; parameters are interpreted per kind (see the factories).
struct SigmaScheme {
  enum class Kind { kScaled = 0, kJulier = 1, kCubature = 2, kHuerta = 3 };
  Kind kind = Kind::kScaled;
  double alpha = 1.0;
  double beta = 2.0;
  double kappa = 0.0;

  /// Scaled unscented transform of Wan and van der Merwe (2000): lambda = alpha^2 (n + kappa) - n,
  /// Wm0 = lambda/(n+lambda), Wc0 = Wm0 + 1 - alpha^2 + beta, Wi = 1/(2(n+lambda)). alpha in (0, 1].
  static SigmaScheme scaled(double alpha = 1e-3, double beta = 2.0, double kappa = 0.0) {
    return {Kind::kScaled, alpha, beta, kappa};
  }
  /// Julier and Uhlmann (1997): W0 = kappa/(n+kappa), Wi = 1/(2(n+kappa)), gamma = sqrt(n+kappa).
  static SigmaScheme julier(double kappa = 0.0) { return {Kind::kJulier, 1.0, 0.0, kappa}; }
  /// Spherical-radial cubature (Arasaratnam and Haykin 2009): 2n points of weight 1/(2n), gamma = sqrt(n);
  /// the centre point is kept with weight 0 so the layout matches the other schemes.
  static SigmaScheme cubature() { return {Kind::kCubature, 1.0, 0.0, 0.0}; }
  /// Huerta et al. 2009, eqs. (49)-(52): lambda = alpha^2 L - L, Wc0 = lambda/(L+lambda) + 3 - alpha^2
  /// (the scaled rule with kappa = 0 and beta = 2).
  static SigmaScheme huerta(double alpha = 1.0) { return {Kind::kHuerta, alpha, 2.0, 0.0}; }

  /// Throws std::invalid_argument unless the parameters give valid weights for dimension n.
  void validate(int n) const {
    NLOSLOC_ENSURE(n > 0, "sigma scheme: dimension n must be > 0");
    switch (kind) {
      case Kind::kScaled:
      case Kind::kHuerta:
        // eq. (52) has no kappa: weights() uses 0, so another value would be ignored (or refused below)
        NLOSLOC_ENSURE(
            kind != Kind::kHuerta || kappa == 0.0,
            "sigma scheme: kappa: expected 0 for the Huerta rule (eq. 52), got " + std::to_string(kappa));
        NLOSLOC_ENSURE(std::isfinite(alpha) && alpha > 0.0 && alpha <= 1.0,
                       "sigma scheme: alpha: expected a value in (0, 1], got " + std::to_string(alpha));
        NLOSLOC_ENSURE(std::isfinite(beta), "sigma scheme: beta: expected a finite value");
        NLOSLOC_ENSURE(std::isfinite(kappa) && n + kappa > 0.0,
                       "sigma scheme: kappa: expected n + kappa > 0, got kappa = " + std::to_string(kappa));
        break;
      case Kind::kJulier:
        NLOSLOC_ENSURE(std::isfinite(kappa) && n + kappa > 0.0,
                       "sigma scheme: kappa: expected n + kappa > 0, got kappa = " + std::to_string(kappa));
        break;
      case Kind::kCubature: break;
      default: detail::throw_invalid_argument("sigma scheme: kind: unknown value");
    }
  }

  /// Weights for an n-dimensional variable.
  SigmaWeights weights(int n) const {
    validate(n);
    const double nd = static_cast<double>(n);
    SigmaWeights w;
    switch (kind) {
      case Kind::kScaled:
      case Kind::kHuerta: {
        const double k = kind == Kind::kHuerta ? 0.0 : kappa;
        const double lambda = alpha * alpha * (nd + k) - nd;  // Wan & van der Merwe; Huerta eq. (52)
        w.gamma = std::sqrt(nd + lambda);                     // Huerta eq. (49): sqrt(alpha^2 L Q)
        w.wm0 = lambda / (nd + lambda);
        w.wc0 = w.wm0 + 1.0 - alpha * alpha + beta;  // Huerta eq. (52) with beta = 2
        w.wi = 1.0 / (2.0 * (nd + lambda));
        break;
      }
      case Kind::kJulier:
        w.gamma = std::sqrt(nd + kappa);
        w.wm0 = w.wc0 = kappa / (nd + kappa);
        w.wi = 1.0 / (2.0 * (nd + kappa));
        break;
      case Kind::kCubature:
        w.gamma = std::sqrt(nd);
        w.wm0 = w.wc0 = 0.0;
        w.wi = 1.0 / (2.0 * nd);
        break;
    }
    return w;
  }
};

inline const char* to_string(SigmaScheme::Kind k) {
  switch (k) {
    case SigmaScheme::Kind::kScaled: return "scaled";
    case SigmaScheme::Kind::kJulier: return "julier";
    case SigmaScheme::Kind::kCubature: return "cubature";
    default: return "huerta";
  }
}

/// Writes the 2n+1 sigma points of (mean, L) as columns of X: X(:,0) = mean, X(:,1..n) = mean + gamma L,
/// X(:,n+1..2n) = mean - gamma L. L is a lower Cholesky factor of the covariance. No allocation.
template <class DM, class DL, class DX>
void sigma_points(const Eigen::MatrixBase<DM>& mean, const Eigen::MatrixBase<DL>& L, double gamma,
                  Eigen::MatrixBase<DX>& X) {
  const Eigen::Index n = mean.size();
  X.col(0) = mean;
  for (Eigen::Index i = 0; i < n; ++i) {
    X.col(1 + i) = mean + gamma * L.col(i);
    X.col(1 + n + i) = mean - gamma * L.col(i);
  }
}

}  // namespace nlosloc
