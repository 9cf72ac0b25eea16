#pragma once
/// \file gcrb.hpp
/// Generalized (posterior) Cramer-Rao bound of Huerta et al. 2009, Appendix: RTOA position with a Gaussian
/// prior of variance sigma_tau^2 on the transmission time (clock), eqs. (41)-(48); 2-D or 3-D.
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "nlosloc/core/types.hpp"

namespace nlosloc::bounds {

/// Result of gcrb_rtoa: the information matrices and the position bounds.
struct GcrbResult {
  MatX J;              ///< (D+1) x (D+1) information J = J_D + J_P, eq. (46)
  MatX J_data;         ///< J_D = H Q^-1 H^T, eq. (43)
  MatX position_gcrb;  ///< D x D [J^-1]_p, eqs. (47)-(48)
  MatX position_crb;   ///< D x D [J_D^-1]_p, the CRB without prior (RTOA/TDOA, Urruela et al. 2006)
};

/// GCRB of the position from RTOA measurements of B anchors (rows of `anchors`, B x D) at mobile position
/// `position` (D), measurement covariance Q (B x B, positive definite, max |Q - Q^T| <= 1e-10 ||Q||_F)
/// and prior variance sigma_tau2 of the clock (> 0; +inf gives the CRB without prior). The unit vectors (cos
/// phi, sin phi) of eq. (44) point from the anchor to the mobile. position_gcrb is the upper-left block of
/// J^-1, computed as the inverse of the Schur complement of J's clock entry (eq. 48 prints the bracket
/// without its outer inverse).
inline GcrbResult gcrb_rtoa(const MatX& anchors, const VecX& position, const MatX& Q, double sigma_tau2) {
  const Eigen::Index B = anchors.rows(), D = anchors.cols();
  NLOSLOC_ENSURE(D == 2 || D == 3, "anchors: expected B x 2 or B x 3 anchor positions");
  NLOSLOC_ENSURE(B >= 1, "anchors: expected at least one anchor");
  detail::ensure_finite(anchors, "anchors");
  detail::ensure_shape(position, D, 1, "position");
  detail::ensure_finite(position, "position");
  detail::ensure_shape(Q, B, B, "Q");
  detail::ensure_finite(Q, "Q");
  NLOSLOC_ENSURE(sigma_tau2 > 0.0, "sigma_tau2: expected a variance > 0 (or +inf for no prior)");
  // A covariance is symmetric: reject rather than silently use the symmetric part of a wrong matrix; the
  // tolerance (relative to ||Q||) only forgives rounding, which the symmetrisation below then removes.
  constexpr double kSymmetryTolerance = 1e-10;
  const double asym = (Q - Q.transpose()).cwiseAbs().maxCoeff();
  if (asym > kSymmetryTolerance * Q.norm()) {
    std::ostringstream msg;
    msg << "Q: expected a symmetric covariance, got max |Q - Q^T| = " << asym << " > " << kSymmetryTolerance
        << " ||Q||";
    detail::throw_invalid_argument(msg.str());
  }
  Eigen::LLT<MatX> llt(0.5 * (Q + Q.transpose()));
  NLOSLOC_ENSURE(llt.info() == Eigen::Success, "Q: expected a symmetric positive definite covariance");
  // eq. (44): H = [H_p; 1^T], columns = unit vectors anchor -> mobile
  MatX H(D + 1, B);
  for (Eigen::Index b = 0; b < B; ++b) {
    const VecX d = position - anchors.row(b).transpose();
    const double r = d.norm();
    NLOSLOC_ENSURE(r > 0.0, "position: coincides with anchor " + std::to_string(b));
    H.col(b).head(D) = d / r;
    H(D, b) = 1.0;
  }
  GcrbResult out;
  out.J_data = H * llt.solve(H.transpose());  // eq. (43)
  out.J = out.J_data;
  if (std::isfinite(sigma_tau2)) out.J(D, D) += 1.0 / sigma_tau2;  // eqs. (45)-(46)
  // eq. (48) via the Schur complement: [J^-1]_p = (J_pp - J_pt J_tt^-1 J_tp)^-1
  auto pos_block = [D](const MatX& J) -> MatX {
    const MatX Jpp = J.topLeftCorner(D, D);
    const VecX Jpt = J.topRightCorner(D, 1);
    const double Jtt = J(D, D);
    const MatX S = Jpp - Jpt * Jpt.transpose() / Jtt;
    Eigen::FullPivLU<MatX> lu(S);
    if (!lu.isInvertible()) return MatX::Constant(D, D, std::numeric_limits<double>::infinity());
    return lu.inverse();
  };
  out.position_gcrb = pos_block(out.J);      // eq. (47)
  out.position_crb = pos_block(out.J_data);  // no prior: [J_D^-1]_p
  return out;
}

}  // namespace nlosloc::bounds
