// Ke & Wu 2011 mitigation (mitigation/*.hpp): eqs. (10)-(15) against hand-computed values on a small
// geometry, the QP adapter, the innovation test (31)-(32), the fallbacks (inconsistent ranges, QP failure,
// no common region) with their flags and a finite state, and the bias-augmented EKF.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <memory>

#include "nlosloc/mitigation/mitigation.hpp"

using namespace nlosloc;
using namespace nlosloc::mitigation;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
MatX small_anchors() { return (MatX(3, 2) << 0, 0, 10, 0, 0, 10).finished(); }
// Exact ranges from (3, 4): 5, sqrt(65), sqrt(45).
VecX exact_ranges() { return (VecX(3) << 5.0, std::sqrt(65.0), std::sqrt(45.0)).finished(); }
Gaussian<4> belief_at(double x, double y) {
  Gaussian<4> g;
  g.mean << x, y, 0, 0;
  g.cov = Mat<4, 4>::Identity();
  return g;
}
ConstantVelocity2 motion() { return ConstantVelocity2(0.1, 1.0, VelocityNoise::kWhiteAcceleration); }
/// set_belief refuses a non-finite time and a belief that is not positive definite (naming them).
template <class Filter>
void check_set_belief_refusals(Filter& f, const Gaussian<4>& b, const Gaussian<4>& bad) {
  CHECK_THROWS_AS(f.set_belief(b, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  CHECK_THROWS_WITH(f.set_belief(b, std::numeric_limits<double>::infinity()),
                    Catch::Matchers::Contains("t: expected a finite time"));
  CHECK_THROWS_AS(f.set_belief(bad), std::invalid_argument);
  CHECK_THROWS_WITH(f.set_belief(bad, 1.0), Catch::Matchers::Contains("belief"));
}
double qp_objective(const MatX& L, const MatX& Sg, const VecX& r, const VecX& b) {
  const VecX e = r - L * b;
  return e.dot(Sg * e);  // eq. (14) objective with the generalised inverse of Sigma_v
}
}  // namespace

TEST_CASE("reference point: vertices of the discs' common region, and the documented fallbacks",
          "[mitigation][reference]") {
  const MatX A = small_anchors();
  // Exact ranges: the three circles meet at (3, 4), the only vertex.
  ReferencePoint rp = reference_point(A, exact_ranges());
  CHECK(rp.kind == ReferenceKind::kFeasibleVertices);
  CHECK_THAT(rp.point[0], WithinAbs(3.0, 1e-9));
  CHECK_THAT(rp.point[1], WithinAbs(4.0, 1e-9));
  // Three equal discs of radius 8 around the corners: vertices (mean of the three inner intersections).
  const VecX z8 = VecX::Constant(3, 8.0);
  rp = reference_point(A, z8);
  CHECK(rp.kind == ReferenceKind::kFeasibleVertices);
  CHECK(rp.vertices == 3);
  // Hand: circles 1-2 meet at (5, sqrt(39)); 1-3 at (sqrt(39), 5); 2-3 at (5 -/+ ..) on the line y = x:
  // x = 5 - sqrt(64 - 50) / sqrt(2) = 5 - sqrt(7) (the one inside disc 1).
  const double v = 5.0 - std::sqrt(7.0);
  CHECK_THAT(rp.point[0], WithinAbs((5.0 + std::sqrt(39.0) + v) / 3.0, 1e-9));
  CHECK_THAT(rp.point[1], WithinAbs((std::sqrt(39.0) + 5.0 + v) / 3.0, 1e-9));
  // Disjoint discs (z1 + z2 < l12): no common point -> hint, else least squares.
  const VecX zbad = (VecX(3) << 3.0, 3.0, 6.0).finished();
  const Vec<2> hint(1.0, 2.0);
  rp = reference_point(A, zbad, &hint);
  CHECK(rp.kind == ReferenceKind::kHint);
  CHECK(rp.point == hint);
  rp = reference_point(A, zbad);
  CHECK(rp.kind == ReferenceKind::kLeastSquares);
  CHECK(rp.point.allFinite());
}

TEST_CASE("eqs. (10)-(15) on a small geometry match hand-computed values", "[mitigation][bias]") {
  BiasEstimator est(small_anchors());
  const VecX z = exact_ranges();
  const BiasEstimate& e = est.estimate(z, VecX::Ones(3));
  REQUIRE(e.flags == kFlagNone);
  // Eq. (10): rows (X0 - a_i)^T / ||X0 - a_i|| at X0 = (3, 4).
  MatX H0(3, 2);
  H0 << 0.6, 0.8, -7.0 / std::sqrt(65.0), 4.0 / std::sqrt(65.0), 3.0 / std::sqrt(45.0),
      -6.0 / std::sqrt(45.0);
  CHECK(est.H0().isApprox(H0, 1e-12));
  // Eq. (11) with R = I: U = -(H0^T H0)^-1 H0^T (numbers from an independent numpy computation).
  MatX U(2, 3);
  U << -0.6176470588235293, 0.6165255925169478, -0.21045345670586255, -0.6029411764705882,
      -0.16598765952379363, 0.48667361863230707;
  CHECK(est.U().isApprox(U, 1e-12));
  CHECK(((est.U() * est.H0()) + Mat<2, 2>::Identity()).norm() < 1e-12);  // -U H0 = I
  // Eq. (12): L = I + H0 U, a projector with L H0 = 0; r = L y = 0 for exact ranges.
  MatX L(3, 3);
  L << 0.1470588235294118, 0.23712522789113377, 0.26306682088232813, 0.23712522789113377, 0.38235294117647056,
      0.42418250299576343, 0.2630668208823282, 0.4241825029957634, 0.47058823529411775;
  CHECK(est.L().isApprox(L, 1e-12));
  CHECK((est.L() * est.H0()).norm() < 1e-12);
  CHECK((est.L() * est.L() - est.L()).norm() < 1e-12);
  CHECK(est.r().norm() < 1e-9);
  CHECK_THAT(e.x_tilde[0], WithinAbs(3.0, 1e-9));
  CHECK_THAT(e.x_tilde[1], WithinAbs(4.0, 1e-9));
  // Eq. (13): Sigma_v = L R L^T (R = I: = L), rank M - 2 = 1; R^-1 L is a generalised inverse.
  CHECK(est.sigma_v().isApprox(L, 1e-12));
  const MatX& Sv = est.sigma_v();
  CHECK((Sv * est.sigma_v_ginv() * Sv - Sv).norm() < 1e-12);
  Eigen::SelfAdjointEigenSolver<MatX> es(Sv);
  CHECK_THAT(es.eigenvalues()[2], WithinAbs(1.0, 1e-12));
  CHECK(std::abs(es.eigenvalues()[0]) < 1e-12);
  CHECK(std::abs(es.eigenvalues()[1]) < 1e-12);
  // Eq. (15): b_i^U = min_j (z_i + z_j - l_ij).
  CHECK_THAT(e.upper[0], WithinAbs(5.0 + std::sqrt(45.0) - 10.0, 1e-12));
  CHECK_THAT(e.upper[1], WithinAbs(std::sqrt(65.0) + std::sqrt(45.0) - std::sqrt(200.0), 1e-12));
  CHECK_THAT(e.upper[2], WithinAbs(std::sqrt(65.0) + std::sqrt(45.0) - std::sqrt(200.0), 1e-12));
  CHECK(e.lower.isZero());
  // Eq. (14): with exact ranges the only feasible zero-residual point is b = 0.
  REQUIRE(e.qp.ok());
  CHECK(e.bias.cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("eq. (14) with a biased range: objective at its minimum, bounds respected", "[mitigation][bias]") {
  BiasEstimator est(small_anchors());
  VecX z = exact_ranges();
  z[2] += 1.5;  // NLOS bias on anchor 3
  const VecX var = (VecX(3) << 0.04, 0.09, 0.01).finished();
  const BiasEstimate& e = est.estimate(z, var);
  REQUIRE(e.qp.ok());
  CHECK(e.flags == kFlagNone);
  CHECK((e.bias.array() >= e.lower.array() - 1e-12).all());
  CHECK((e.bias.array() <= e.upper.array() + 1e-12).all());
  const double f_hat = qp_objective(est.L(), est.sigma_v_ginv(), est.r(), e.bias);
  CHECK(f_hat <= qp_objective(est.L(), est.sigma_v_ginv(), est.r(), VecX::Zero(3)) + 1e-12);
  // The rank-1 objective reaches 0 inside the box (the true bias is feasible): b^ attains it.
  CHECK(f_hat < 1e-6);
  // Sigma_v = L R L^T for a non-identity R, and the generalised-inverse identity still holds.
  const MatX Sv = est.L() * var.asDiagonal() * est.L().transpose();
  CHECK(est.sigma_v().isApprox(Sv, 1e-12));
  CHECK((Sv * est.sigma_v_ginv() * Sv - Sv).norm() < 1e-12 * Sv.norm());
}

TEST_CASE("eq. (14) referenced to the prediction (r = innovation, Sigma_v = eq. 27): unique minimiser",
          "[mitigation][bias]") {
  BiasEstimator est(small_anchors());
  const VecX z = VecX::Constant(3, 20.0);
  // Eq. (15) by hand: l12 = l13 = 10, l23 = sqrt(200); b^U = (40 - 10, 40 - sqrt(200), 40 - sqrt(200)).
  const double u23 = 40.0 - std::sqrt(200.0);
  // D = [[2, 1, 0], [1, 2, 0], [0, 0, 1]], r = (1, -1, 0). With b_2 at 0 the stationarity in b_1 of
  // (r - b)^T D^-1 (r - b), D^-1 = [[2, -1, 0], [-1, 2, 0], [0, 0, 3]] / 3, gives 2 e_1 = e_2 = -1, i.e.
  // b_1 = 1.5; the gradient in b_2 is -2 (D^-1 e)_2 = -2 (0.5 - 2) / 3 = 1 > 0, so b_2 = 0 is optimal.
  MatX D(3, 3);
  D << 2, 1, 0, 1, 2, 0, 0, 0, 1;
  const BiasEstimate& e = est.estimate_from_innovation(z, Vec<3>(1.0, -1.0, 0.0), D);
  REQUIRE(e.qp.ok());
  CHECK(e.flags == kFlagNone);
  CHECK_THAT(e.upper[0], WithinAbs(30.0, 1e-12));
  CHECK_THAT(e.upper[1], WithinAbs(u23, 1e-12));
  CHECK_THAT(e.upper[2], WithinAbs(u23, 1e-12));
  CHECK_THAT(e.bias[0], WithinAbs(1.5, 1e-6));
  CHECK_THAT(e.bias[1], WithinAbs(0.0, 1e-6));
  CHECK_THAT(e.bias[2], WithinAbs(0.0, 1e-6));
  CHECK(est.L().isIdentity(0.0));
  CHECK(est.sigma_v().isApprox(D, 1e-15));
  CHECK((est.sigma_v_ginv() * D - MatX::Identity(3, 3)).norm() < 1e-12);
  // D = I: b^ is r clipped to the box, the upper bound of eq. (15) included.
  const BiasEstimate& e2 = est.estimate_from_innovation(z, Vec<3>(40.0, -1.0, 0.5), MatX::Identity(3, 3));
  REQUIRE(e2.qp.ok());
  CHECK_THAT(e2.bias[0], WithinAbs(30.0, 1e-6));
  CHECK_THAT(e2.bias[1], WithinAbs(0.0, 1e-6));
  CHECK_THAT(e2.bias[2], WithinAbs(0.5, 1e-6));
  // Shapes named (D's other checks: the next test case).
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, VecX::Zero(3), MatX::Identity(2, 2)),
                    Catch::Matchers::Contains("D"));
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, VecX::Zero(2), MatX::Identity(3, 3)),
                    Catch::Matchers::Contains("innovation"));
  // inf is an input error (named), NaN a missing row (flagged); a rejected call keeps the last estimate.
  const VecX zinf = Vec<3>(20.0, std::numeric_limits<double>::infinity(), 20.0);
  CHECK_THROWS_WITH(
      est.estimate_from_innovation(zinf, Vec<3>(40.0, -1.0, 0.5), MatX::Identity(3, 3)),
      Catch::Matchers::Equals("z: expected finite values, or NaN for a missing row; got inf at row 1"));
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, zinf, MatX::Identity(3, 3)),
                    Catch::Matchers::Contains("innovation: expected finite values") &&
                        Catch::Matchers::Contains("got inf at row 1"));
  CHECK_THROWS_WITH(est.estimate(zinf, VecX::Ones(3)),
                    Catch::Matchers::Contains("z: expected finite values"));
  CHECK_THAT(est.last().bias[0], WithinAbs(30.0, 1e-6));  // e2's estimate, untouched
  CHECK_THAT(est.last().bias[2], WithinAbs(0.5, 1e-6));
  const VecX znan = Vec<3>(20.0, std::nan(""), 20.0);
  CHECK((est.estimate_from_innovation(znan, Vec<3>(1, 1, 1), MatX::Identity(3, 3)).flags &
         kFlagMissingRows) != 0);
}

TEST_CASE("eq. (27)'s D must be a covariance: finite, symmetric, positive definite, else named",
          "[mitigation][bias][input]") {
  BiasEstimator est(small_anchors());
  const VecX z = VecX::Constant(3, 20.0);
  MatX D(3, 3);
  D << 2, 1, 0, 1, 2, 0, 0, 0, 1;
  REQUIRE(est.estimate_from_innovation(z, Vec<3>(1.0, -1.0, 0.0), D).qp.ok());
  const VecX bias = est.last().bias;
  const MatX Sv = est.sigma_v(), Svg = est.sigma_v_ginv(), Hq = est.qp_hessian();
  const VecX r = est.r(), gq = est.qp_gradient();
  const Vec<3> innov(5.0, 3.0, 1.0);
  // Was silently symmetrised.
  MatX asym = D;
  asym(0, 1) = 1.5;
  asym(1, 0) = -1.5;
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, innov, asym),
                    "D: expected a symmetric matrix, got D[0,1] = 1.5 != D[1,0] = -1.5");
  // Were reported as DEGENERATE_GEOMETRY (flags 8); the header promised an exception on inf.
  MatX inf = D;
  inf(2, 2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, innov, inf), "D: expected finite values (no NaN or inf)");
  inf(2, 2) = std::nan("");
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, innov, inf), "D: expected finite values (no NaN or inf)");
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, innov, -MatX::Identity(3, 3)),
                    "D: expected a positive definite matrix (eq. 27: F P F^T + R), got the pivot -1 at row 0 "
                    "of its Cholesky factorisation");
  // Indefinite: the second pivot of [[1, 2], [2, 1]] is 1 - 2^2 = -3; singular PSD: a zero pivot.
  MatX indef = MatX::Identity(3, 3);
  indef(0, 1) = indef(1, 0) = 2.0;
  CHECK_THROWS_WITH(est.estimate_from_innovation(z, innov, indef),
                    "D: expected a positive definite matrix (eq. 27: F P F^T + R), got the pivot -3 at row 1 "
                    "of its Cholesky factorisation");
  CHECK_THROWS_WITH(
      est.estimate_from_innovation(z, innov, Vec<3>(1.0, 0.0, 1.0).asDiagonal().toDenseMatrix()),
      "D: expected a positive definite matrix (eq. 27: F P F^T + R), got the pivot 0 at row 1 "
      "of its Cholesky factorisation");
  // D is checked even when a missing range means no estimate.
  CHECK_THROWS_WITH(est.estimate_from_innovation(Vec<3>(20.0, std::nan(""), 20.0), innov, asym),
                    Catch::Matchers::StartsWith("D: expected a symmetric matrix"));
  // Unchanged by the refused calls.
  CHECK(est.last().bias == bias);
  CHECK(est.last().flags == kFlagNone);
  CHECK(est.sigma_v() == Sv);
  CHECK(est.sigma_v_ginv() == Svg);
  CHECK(est.qp_hessian() == Hq);
  CHECK(est.qp_gradient() == gq);
  CHECK(est.r() == r);
  // Round-off asymmetry (1e-12 of max |D|, as F P F^T + R computed in floating point) passes.
  MatX near = D;
  near(0, 1) += 2e-12;
  const BiasEstimate& e = est.estimate_from_innovation(z, Vec<3>(1.0, -1.0, 0.0), near);
  REQUIRE(e.qp.ok());
  CHECK_THAT(e.bias[0], WithinAbs(1.5, 1e-6));
}

TEST_CASE("reference point: anchors M x 2 (M >= 2) finite, ranges finite and >= 0, else named",
          "[mitigation][reference][input]") {
  const MatX A = small_anchors();
  CHECK_THROWS_WITH(reference_point(A, Vec<3>(5.0, -1.0, 6.0)),
                    "z: expected finite ranges >= 0 (m), got -1 at row 1");
  CHECK_THROWS_WITH(reference_point(A, Vec<3>(5.0, 6.0, std::numeric_limits<double>::infinity())),
                    "z: expected finite ranges >= 0 (m), got inf at row 2");
  CHECK_THROWS_WITH(reference_point(A, Vec<3>(std::nan(""), 6.0, 7.0)),
                    "z: expected finite ranges >= 0 (m), got nan at row 0");
  CHECK_THROWS_WITH(reference_point(A, Vec<2>(5.0, 6.0)), "z: expected shape (3, 1), got (2, 1)");
  CHECK_THROWS_WITH(reference_point(A.topRows(1), Vec<1>(5.0)),
                    "anchors: expected at least 2 anchors (rows), got 1");
  MatX bad = A;
  bad(1, 0) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(reference_point(bad, exact_ranges()), "anchors: expected finite values (no NaN or inf)");
  CHECK_THROWS_WITH(reference_point(MatX::Zero(3, 3), exact_ranges()),
                    "anchors: expected shape (-1, 2), got (3, 3)");
  // Two anchors and zero ranges are valid: circles of radius 6 around (0, 0) and (10, 0) meet at (5,
  // +-sqrt(11)), whose mean is (5, 0); a zero range is a point disc.
  const ReferencePoint two = reference_point(A.topRows(2), Vec<2>(6.0, 6.0));
  CHECK(two.kind == ReferenceKind::kFeasibleVertices);
  CHECK(two.vertices == 2);
  CHECK_THAT(two.point[0], WithinAbs(5.0, 1e-12));
  CHECK_THAT(two.point[1], WithinAbs(0.0, 1e-12));
  const ReferencePoint zero = reference_point(A.topRows(2), Vec<2>(0.0, 10.0));
  CHECK(zero.kind == ReferenceKind::kFeasibleVertices);  // tangent at anchor 0
  CHECK(zero.point.norm() < 1e-12);
  // BiasEstimator::estimate takes a negative range (noise near an anchor), as before: no exception.
  BiasEstimator est(A);
  VecX zneg = exact_ranges();
  zneg[0] = -0.5;
  CHECK_NOTHROW(est.estimate(zneg, VecX::Ones(3)));
  CHECK(est.last().bias.allFinite());
}

TEST_CASE("QpBiasEkfOptions::validate refuses what the constructor refuses, with the same message",
          "[mitigation][input]") {
  const auto refused_alike = [](const QpBiasEkfOptions& o, const std::string& msg) {
    CHECK_THROWS_WITH(o.validate(), msg);
    CHECK_THROWS_WITH(QpBiasEkf(motion(), small_anchors(), belief_at(3, 4), o), msg);
  };
  QpBiasEkfOptions o;
  o.sparsity = -1.0;  // validate() passed it, the constructor said "sparsity: ..."
  refused_alike(o, "options.sparsity: expected a finite value >= 0, got -1.000000");
  o.sparsity = std::numeric_limits<double>::infinity();
  refused_alike(o, "options.sparsity: expected a finite value >= 0, got inf");
  o.sparsity = 0.5;
  o.reference = static_cast<BiasReference>(7);
  refused_alike(o, "options.reference: expected BiasReference::kPrediction (0) or kSnapshot (1), got 7");
  o.reference = BiasReference::kSnapshot;
  o.soft_threshold = -2.0;
  refused_alike(o, "options.soft_threshold: expected a finite value >= 0, got -2.000000");
  o.soft_threshold = 0.0;
  o.gamma = 0.9;
  refused_alike(o, "options.gamma: expected a finite value >= 1 (eq. 32), got 0.900000");
  o.gamma = 1.1;
  o.noise.min_std = 0.0;
  refused_alike(o, "options.noise.min_std: expected a finite value > 0, got 0.000000");
  o.noise.min_std = 1e-3;
  o.validate();
  const QpBiasEkf f(motion(), small_anchors(), belief_at(3, 4), o);
  CHECK(f.bias_estimator().sparsity() == 0.5);
}

TEST_CASE("soft threshold on eq. (14): b = clip(r - lambda sqrt(D_ii), 0, b^U) for diagonal D",
          "[mitigation][bias]") {
  BiasEstimator est(small_anchors());
  const VecX z = VecX::Constant(3, 20.0);
  const double u23 = 40.0 - std::sqrt(200.0);  // eq. (15), as in the test above
  // D = diag(1, 4, 9), lambda = 2: thresholds 2, 4, 6. r = (5, 3, 40): b = (3, 0, min(34, b^U_3) = b^U_3).
  Vec<3> dg(1.0, 4.0, 9.0);
  const MatX D = dg.asDiagonal();
  est.set_soft_threshold(2.0);
  CHECK(est.soft_threshold() == 2.0);
  const BiasEstimate& e = est.estimate_from_innovation(z, Vec<3>(5.0, 3.0, 40.0), D);
  REQUIRE(e.qp.ok());
  CHECK_THAT(e.bias[0], WithinAbs(3.0, 1e-6));
  CHECK_THAT(e.bias[1], WithinAbs(0.0, 1e-6));
  CHECK_THAT(e.bias[2], WithinAbs(u23, 1e-6));
  // lambda = 0 is eq. (14): every positive innovation read as bias.
  est.set_soft_threshold(0.0);
  const BiasEstimate& e0 = est.estimate_from_innovation(z, Vec<3>(5.0, 3.0, 40.0), D);
  CHECK_THAT(e0.bias[0], WithinAbs(5.0, 1e-6));
  CHECK_THAT(e0.bias[1], WithinAbs(3.0, 1e-6));
  CHECK_THROWS_WITH(est.set_soft_threshold(-1.0), Catch::Matchers::StartsWith("soft_threshold: expected"));
  CHECK(est.soft_threshold() == 0.0);
  QpBiasEkfOptions o;
  o.soft_threshold = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(o.validate(), Catch::Matchers::StartsWith("options.soft_threshold: expected a finite"));
}

TEST_CASE("proposed update: rows whose b^ is inside its box are left out, the others use z - b^",
          "[mitigation][bias]") {
  QpBiasEkfOptions o;
  o.noise.sigma0 = 0.1;
  o.always_estimate = true;
  VecX z = exact_ranges();
  z[2] += 3.0;  // NLOS excess on anchor 3, the prediction sits at the truth
  QpBiasEkf f(motion(), small_anchors(), belief_at(3, 4), o);
  const MitigationStep s = f.update(z);
  REQUIRE(s.bias_estimated);
  const VecX b = f.bias();
  const BiasEstimate& be = f.bias_estimator().last();
  CHECK(b[2] > 1.0);  // most of the excess is attributed to anchor 3
  // Expected update, by hand: a plain EKF (eqs. 22-24) on z - b^ with the interior rows missing.
  VecX zc = z - b;
  int dropped = 0;
  for (int i = 0; i < 3; ++i)
    if (b[i] > be.lower[i] + 1e-6 && b[i] < be.upper[i] - 1e-6) {
      zc[i] = std::nan("");
      ++dropped;
    }
  CHECK(dropped >= 1);
  CHECK(s.rows_dropped == dropped);
  CHECK(s.filter.rows_used == 3 - dropped);
  QpBiasEkfOptions plain = o;
  plain.mitigate = false;
  QpBiasEkf g(motion(), small_anchors(), belief_at(3, 4), plain);
  g.update(zc);
  CHECK(f.mean().isApprox(g.mean(), 1e-9));
  CHECK(f.cov().isApprox(g.cov(), 1e-9));
  // drop_free_rows = false: eq. (25) on every row (z - b^ with variance R).
  QpBiasEkfOptions keep = o;
  keep.drop_free_rows = false;
  QpBiasEkf h(motion(), small_anchors(), belief_at(3, 4), keep);
  const MitigationStep sk = h.update(z);
  CHECK(sk.rows_dropped == 0);
  QpBiasEkf g2(motion(), small_anchors(), belief_at(3, 4), plain);
  g2.update(VecX(z - h.bias()));
  CHECK(h.mean().isApprox(g2.mean(), 1e-9));
  // The literal Sec. 3 form stays available: its L is the rank M - 2 projector, not I.
  QpBiasEkfOptions snap = o;
  snap.reference = BiasReference::kSnapshot;
  QpBiasEkf q(motion(), small_anchors(), belief_at(3, 4), snap);
  q.update(z);
  CHECK(q.bias_estimator().L().trace() < 1.5);  // trace of a rank-1 projector is 1
  CHECK(q.mean().allFinite());
}

TEST_CASE("inconsistent ranges: eq. (15) lower > upper is clamped and flagged, result finite",
          "[mitigation][fallback]") {
  BiasEstimator est(small_anchors());
  const VecX z = (VecX(3) << 3.0, 3.0, 6.0).finished();  // z1 + z2 < l12 = 10
  const Vec<2> hint(2.0, 2.0);
  const BiasEstimate& e = est.estimate(z, VecX::Ones(3), &hint);
  CHECK((e.flags & kFlagBoundsClamped) != 0);
  CHECK((e.flags & kFlagReferenceFallback) != 0);
  CHECK(e.upper[0] == 0.0);
  CHECK(e.upper[1] == 0.0);
  CHECK(e.bias.allFinite());
  CHECK((e.bias.array() >= 0.0).all());
  CHECK((e.bias.array() <= e.upper.array()).all());

  // The tracker on the same inconsistent ranges: flags propagate, the state stays finite.
  QpBiasEkfOptions o;
  o.noise.sigma0 = 0.1;
  o.always_estimate = true;
  QpBiasEkf f(motion(), small_anchors(), belief_at(3, 4), o);
  const MitigationStep s = f.update(z);
  CHECK((s.flags & kFlagBoundsClamped) != 0);
  CHECK(s.bias_estimated);
  CHECK(f.mean().allFinite());
  CHECK(f.cov().allFinite());
}

TEST_CASE("QP failure: b = 0, flag set, update equals the plain EKF's", "[mitigation][fallback]") {
  QpBiasEkfOptions o;
  o.noise.sigma0 = 0.5;
  o.always_estimate = true;
  QpBiasEkf f(motion(), small_anchors(), belief_at(2.5, 4.5), o, std::make_unique<FailingBoxQp>(3));
  QpBiasEkfOptions plain = o;
  plain.mitigate = false;
  QpBiasEkf g(motion(), small_anchors(), belief_at(2.5, 4.5), plain);
  VecX z = exact_ranges();
  z[1] += 3.0;
  const MitigationStep s = f.update(z);
  g.update(z);
  CHECK((s.flags & kFlagQpFailed) != 0);
  CHECK(s.bias_estimated);
  CHECK(f.bias().isZero());
  CHECK(f.mean().allFinite());
  CHECK(f.mean().isApprox(g.mean(), 1e-12));
  CHECK(f.cov().isApprox(g.cov(), 1e-12));
  // A wrong-sized solver is rejected, naming the argument.
  CHECK_THROWS_WITH(
      QpBiasEkf(motion(), small_anchors(), belief_at(0, 0), o, std::make_unique<FailingBoxQp>(4)),
      Catch::Matchers::Contains("solver"));
}

TEST_CASE("innovation test, eqs. (31)-(32): LOS below gamma Tr(S), NLOS above", "[mitigation][test]") {
  QpBiasEkfOptions o;
  o.noise.sigma0 = 1.0;  // R = I
  QpBiasEkf f(motion(), small_anchors(), belief_at(3, 4), o);
  // F P F^T has unit diagonal (unit range gradients, P_pos = I): Tr(S) = 3 + 3 = 6, threshold 6.6.
  VecX z = exact_ranges().array() + 1.0;  // alpha^T alpha = 3 <= 6.6: LOS
  MitigationStep s = f.update(z);
  CHECK_THAT(s.threshold, WithinRel(6.6, 1e-12));
  CHECK_THAT(s.innovation_sq, WithinRel(3.0, 1e-12));
  CHECK_FALSE(s.nlos);
  CHECK_FALSE(s.bias_estimated);
  CHECK(f.bias().isZero());

  QpBiasEkf f2(motion(), small_anchors(), belief_at(3, 4), o);
  z = exact_ranges();
  z[2] += 3.0;  // alpha^T alpha = 9 > 6.6: NLOS, QP runs, bias subtracted (eq. 25)
  s = f2.update(z);
  CHECK(s.nlos);
  CHECK(s.bias_estimated);
  CHECK(f2.nlos_detected());
  CHECK(f2.bias().sum() > 0.0);
  // gamma validated, naming the option.
  o.gamma = 0.5;
  CHECK_THROWS_WITH(QpBiasEkf(motion(), small_anchors(), belief_at(0, 0), o),
                    Catch::Matchers::Contains("gamma"));
}

TEST_CASE("bad input leaves the tracker unchanged, missing rows are skipped", "[mitigation][input]") {
  QpBiasEkf f(motion(), small_anchors(), belief_at(3, 4));
  const Vec<4> x0 = f.mean();
  CHECK_THROWS_WITH(f.step(VecX::Ones(2)), Catch::Matchers::Equals("z: expected shape (3, 1), got (2, 1)"));
  CHECK(f.mean() == x0);
  CHECK(f.time() == 0.0);
  VecX zi = exact_ranges();
  zi[2] = std::numeric_limits<double>::infinity();  // inf is an error, not a missing row
  CHECK_THROWS_WITH(f.step(zi), Catch::Matchers::Equals(
                                    "z: expected finite values, or NaN for a missing row; got inf at row 2"));
  CHECK(f.mean() == x0);
  CHECK(f.time() == 0.0);
  // set_belief without a time keeps the time (as FilterBase::set_belief does).
  f.predict();
  f.set_belief(belief_at(5, 6));
  CHECK(f.time() == motion().dt());
  CHECK(f.mean()[0] == 5.0);
  VecX z = exact_ranges();
  z[1] = std::nan("");
  QpBiasEkfOptions o;
  o.always_estimate = true;
  QpBiasEkf g(motion(), small_anchors(), belief_at(3, 4), o);
  const MitigationStep s = g.step(z);
  CHECK(s.filter.rows_used == 2);
  CHECK((s.flags & kFlagMissingRows) != 0);
  CHECK(g.mean().allFinite());
}

TEST_CASE("box QP adapter: clipped diagonal problem and argument checks", "[mitigation][qp]") {
  auto qp = make_box_qp(3);
  // min 1/2 x^T diag(2, 0, 1) x + g^T x, g = (-4, 1, 3), 0 <= x <= (1, 5, 5): x = (1, 0, 0).
  const MatX H = Vec<3>(2, 0, 1).asDiagonal();
  const VecX g = Vec<3>(-4, 1, 3);
  const QpResult r = qp->solve(H, g, VecX::Zero(3), Vec<3>(1, 5, 5));
  REQUIRE(r.ok());
  CHECK((qp->x() - Vec<3>(1, 0, 0)).norm() < 1e-7);
  CHECK_THAT(r.objective, WithinAbs(1.0 - 4.0, 1e-7));
  CHECK_THROWS_WITH(qp->solve(H, g, VecX::Ones(3), VecX::Zero(3)), Catch::Matchers::Contains("lower"));
  CHECK_THROWS_WITH(qp->solve(H, VecX::Zero(2), VecX::Zero(3), VecX::Ones(3)),
                    Catch::Matchers::Contains("g"));
  CHECK(std::string(to_string(QpStatus::kMaxIterations)) == "max_iterations");
}

TEST_CASE("bias-augmented EKF: biases estimated, non-negative, state finite", "[mitigation][augmented]") {
  BiasAugmentedEkfOptions o;
  o.noise.sigma0 = 0.1;
  o.bias_prior_std = 5.0;
  o.bias_walk_std = 0.01;
  ConstantVelocity2 mo(0.1, 1e-4, VelocityNoise::kWhiteAcceleration);
  Gaussian<4> g = belief_at(3, 4);
  g.cov = Vec<4>(0.01, 0.01, 1e-4, 1e-4).asDiagonal();  // tight position prior: the bias is identifiable
  BiasAugmentedEkf f(mo, small_anchors(), g, o);
  CHECK(f.state_dim() == 7);
  VecX z = exact_ranges();
  z[0] += 2.0;
  for (int k = 0; k < 50; ++k) f.step(z);
  CHECK(f.mean().allFinite());
  CHECK((f.bias().array() >= 0.0).all());
  CHECK_THAT(f.bias()[0], WithinAbs(2.0, 0.3));
  CHECK(f.bias().tail(2).cwiseAbs().maxCoeff() < 0.3);
  CHECK_THROWS_WITH(BiasAugmentedEkf(mo, small_anchors(), g,
                                     [] {
                                       BiasAugmentedEkfOptions b;
                                       b.iterations = 0;
                                       return b;
                                     }()),
                    Catch::Matchers::Contains("iterations"));
}

TEST_CASE("bias-augmented EKF: set_augmented_belief restores the whole state, or refuses unchanged",
          "[mitigation][augmented][input]") {
  BiasAugmentedEkfOptions o;
  o.bias_prior_std = 4.0;
  BiasAugmentedEkf f(motion(), small_anchors(), belief_at(3, 4), o, 2.0);
  VecX z = exact_ranges();
  z[1] += 2.5;
  for (int k = 0; k < 5; ++k) f.step(z);
  // a second filter set from the first's mean, covariance and time steps on exactly as the first
  BiasAugmentedEkf g(motion(), small_anchors(), belief_at(0, 0), o);
  g.set_augmented_belief(Gaussian<Eigen::Dynamic>(f.mean(), f.cov()), f.time());
  for (int k = 0; k < 5; ++k) {
    f.step(z);
    g.step(z);
  }
  CHECK(g.mean() == f.mean());
  CHECK(g.cov() == f.cov());
  CHECK(g.time() == f.time());
  const VecX m = f.mean();
  const MatX P = f.cov();
  MatX asym = P;
  asym(0, 5) += 0.5;
  CHECK_THROWS_WITH(
      f.set_augmented_belief(Gaussian<Eigen::Dynamic>(VecX::Zero(4), MatX::Identity(4, 4)), 0.0),
      Catch::Matchers::StartsWith("belief.mean: expected shape (7, 1)"));
  CHECK_THROWS_WITH(f.set_augmented_belief(Gaussian<Eigen::Dynamic>(m, asym), 0.0),
                    "belief.cov: expected a symmetric positive definite matrix");
  CHECK_THROWS_WITH(f.set_augmented_belief(Gaussian<Eigen::Dynamic>(m, P), std::nan("")),
                    "t: expected a finite time (s)");
  CHECK(f.mean() == m);
  CHECK(f.cov() == P);
}

TEST_CASE("set_belief(b) keeps the time, set_belief(b, t) sets it: bias-augmented EKF and QP-bias EKF",
          "[mitigation][input]") {
  // A belief with every entry set (correlated covariance), applied after three steps (t = 0.3 s from
  // t0 = 2 s): mean and covariance become b exactly, the time stays; with t it becomes t. Invalid
  // arguments are refused, naming them, before anything changes.
  Gaussian<4> b;
  b.mean << 5.5, 6.25, 0.75, -0.5;
  b.cov << 2.0, 0.3, 0.1, 0.0,  //
      0.3, 1.5, 0.0, 0.05,      //
      0.1, 0.0, 0.4, 0.02,      //
      0.0, 0.05, 0.02, 0.3;
  Gaussian<4> bad = b;
  bad.cov(0, 0) = -1.0;
  VecX z = exact_ranges();
  z[2] += 3.0;  // NLOS on anchor 2: the QP-bias EKF estimates a bias
  SECTION("BiasAugmentedEkf") {
    BiasAugmentedEkfOptions o;
    o.bias_prior_mean = 0.25;
    o.bias_prior_std = 4.0;
    BiasAugmentedEkf f(motion(), small_anchors(), belief_at(3, 4), o, 2.0);
    for (int k = 0; k < 3; ++k) f.step(z);
    const double t = f.time();
    CHECK_THAT(t, WithinAbs(2.3, 1e-12));
    REQUIRE(f.bias() != VecX::Constant(3, 0.25));  // the steps moved the biases off their prior
    f.set_belief(b);
    CHECK(f.time() == t);
    CHECK(f.kinematic_mean() == b.mean);
    CHECK(MatX(f.cov().topLeftCorner(4, 4)) == MatX(b.cov));
    // the biases restart from the options' prior, uncorrelated with the kinematics
    CHECK(f.bias() == VecX::Constant(3, 0.25));
    CHECK(MatX(f.cov().bottomRightCorner(3, 3)) == MatX(16.0 * MatX::Identity(3, 3)));
    CHECK(f.cov().topRightCorner(4, 3).isZero(0.0));
    f.step(z);  // and the next step starts from that time
    CHECK(f.time() == t + motion().dt());
    f.set_belief(b, 7.25);
    CHECK(f.time() == 7.25);
    CHECK(f.kinematic_mean() == b.mean);
    CHECK(MatX(f.cov().topLeftCorner(4, 4)) == MatX(b.cov));
    const VecX x0 = f.mean();
    check_set_belief_refusals(f, b, bad);
    CHECK(f.time() == 7.25);
    CHECK(f.mean() == x0);
  }
  SECTION("QpBiasEkf") {
    QpBiasEkfOptions o;
    o.noise.sigma0 = 1.0;
    QpBiasEkf f(motion(), small_anchors(), belief_at(3, 4), o, nullptr, 2.0);
    for (int k = 0; k < 3; ++k) f.step(z);
    const double t = f.time();
    CHECK_THAT(t, WithinAbs(2.3, 1e-12));
    REQUIRE(f.nlos_detected());
    REQUIRE(f.bias().sum() > 0.0);
    f.set_belief(b);
    CHECK(f.time() == t);
    CHECK(f.mean() == b.mean);
    CHECK(f.cov() == b.cov);
    // the last bias and decision are cleared
    CHECK(f.bias().isZero(0.0));
    CHECK_FALSE(f.nlos_detected());
    f.step(exact_ranges());
    CHECK(f.time() == t + motion().dt());
    f.set_belief(b, 7.25);
    CHECK(f.time() == 7.25);
    CHECK(f.mean() == b.mean);
    CHECK(f.cov() == b.cov);
    check_set_belief_refusals(f, b, bad);
    CHECK(f.time() == 7.25);
    CHECK(f.mean() == b.mean);
  }
}
