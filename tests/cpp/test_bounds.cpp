// GCRB of Huerta's Appendix (eqs. 41-48): never above the CRB without prior, equal to an independently
// computed CRB under a vague prior, the hand formula on a symmetric geometry, and the checks of Q.
#include <catch2/catch.hpp>

#include "nlosloc/bounds/gcrb.hpp"
#include "nlosloc/core/random.hpp"

using namespace nlosloc;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

TEST_CASE("GCRB is never above the no-prior CRB", "[bounds]") {
  Rng rng(17);
  for (int rep = 0; rep < 200; ++rep) {
    const int B = 3 + static_cast<int>(rng.below(5));
    MatX anchors(B, 2);
    for (int b = 0; b < B; ++b) {
      anchors(b, 0) = 3000 * (2 * rng.uniform() - 1);
      anchors(b, 1) = 3000 * (2 * rng.uniform() - 1);
    }
    const VecX p = Eigen::Vector2d(500 * rng.normal(), 500 * rng.normal());
    MatX A = MatX::Random(B, B);
    const MatX Q = A * A.transpose() + MatX::Identity(B, B) * (1 + 10 * rng.uniform());
    const double s2 = std::exp(4 * rng.normal());
    const auto r = bounds::gcrb_rtoa(anchors, p, Q, s2);
    const Eigen::SelfAdjointEigenSolver<MatX> es(r.position_crb - r.position_gcrb);
    CHECK(es.eigenvalues().minCoeff() >= -1e-9 * r.position_crb.norm());
    CHECK(r.position_gcrb.trace() <= r.position_crb.trace() * (1 + 1e-12));
  }
}

TEST_CASE("GCRB by hand and the no-prior limit", "[bounds]") {
  // four anchors on the axes, mobile at the centre, Q = q I: H_p H_p^T = 2 I, H_p 1 = 0, so the clock
  // decouples and [J^-1]_p = q/2 I with or without prior.
  MatX anchors(4, 2);
  anchors << 100, 0, -100, 0, 0, 100, 0, -100;
  const VecX p = VecX::Zero(2);
  const auto r = bounds::gcrb_rtoa(anchors, p, 10.0 * MatX::Identity(4, 4), 10.0);
  CHECK(r.position_gcrb.isApprox(5.0 * MatX::Identity(2, 2), 1e-12));
  CHECK_THAT(r.J(2, 2), WithinRel(4.0 / 10.0 + 1.0 / 10.0, 1e-12));
  // asymmetric geometry: the prior helps, and a vague prior (sigma_tau^2 = 1e10, still finite so the prior
  // term is added) gives back the CRB, computed here independently: J_D = H H^T / q (eqs. 43-44) built by
  // hand and inverted whole, no Schur complement.
  MatX a3(3, 2);
  a3 << 1000, 0, 0, 1000, 700, 700;
  const VecX p3 = Eigen::Vector2d(10, 20);
  const auto r3 = bounds::gcrb_rtoa(a3, p3, 10.0 * MatX::Identity(3, 3), 10.0);
  CHECK(r3.position_gcrb.trace() < r3.position_crb.trace());
  MatX H(3, 3);
  for (int b = 0; b < 3; ++b) {
    const Eigen::Vector2d d = p3 - a3.row(b).transpose();
    H.col(b) << d / d.norm(), 1.0;
  }
  const MatX JD = H * H.transpose() / 10.0;
  const MatX crb = JD.inverse().topLeftCorner(2, 2);
  const auto vague = bounds::gcrb_rtoa(a3, p3, 10.0 * MatX::Identity(3, 3), 1e10);
  CHECK(vague.J_data.isApprox(JD, 1e-12));
  CHECK_THAT(vague.J(2, 2) - vague.J_data(2, 2), WithinRel(1e-10, 1e-5));  // the prior was added
  CHECK(vague.position_crb.isApprox(crb, 1e-9));
  CHECK(vague.position_gcrb.isApprox(crb, 1e-6));
  CHECK_FALSE(r3.position_gcrb.isApprox(crb, 1e-3));  // an informative prior is not the limit
  CHECK_THROWS_AS(bounds::gcrb_rtoa(a3, p3, MatX::Identity(2, 2), 1.0), std::invalid_argument);
  CHECK_THROWS_AS(bounds::gcrb_rtoa(a3, p3, MatX::Identity(3, 3), 0.0), std::invalid_argument);
}

TEST_CASE("GCRB rejects a non-symmetric Q instead of symmetrising it", "[bounds]") {
  MatX a3(3, 2);
  a3 << 1000, 0, 0, 1000, 700, 700;
  const VecX p3 = Eigen::Vector2d(10, 20);
  MatX Q = 10.0 * MatX::Identity(3, 3);
  Q(0, 1) = 0.5;  // Q(1, 0) stays 0: its symmetric part is SPD, so only the symmetry check catches it
  CHECK_THROWS_WITH(bounds::gcrb_rtoa(a3, p3, Q, 10.0),
                    "Q: expected a symmetric covariance, got max |Q - Q^T| = 0.5 > 1e-10 ||Q||");
  // rounding-level asymmetry (relative 1e-13) is accepted and gives the symmetric result
  MatX Qr = 10.0 * MatX::Identity(3, 3);
  Qr(0, 1) = 1e-12;
  const auto r = bounds::gcrb_rtoa(a3, p3, Qr, 10.0);
  const auto r0 = bounds::gcrb_rtoa(a3, p3, 10.0 * MatX::Identity(3, 3), 10.0);
  CHECK(r.position_gcrb.isApprox(r0.position_gcrb, 1e-9));
}
