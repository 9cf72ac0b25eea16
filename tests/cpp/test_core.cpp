// Core: sigma-point weights, Cholesky fallback, log-sum-exp, RNG.
#include <catch2/catch.hpp>

#include "nlosloc/core/cholesky.hpp"
#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/core/sigma_points.hpp"

using namespace nlosloc;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

TEST_CASE("scaled sigma weights match Wan-van der Merwe by hand", "[core][sigma]") {
  // n = 4, alpha = 0.5, beta = 2, kappa = 1: lambda = 0.25*5 - 4 = -2.75, n+lambda = 1.25.
  const SigmaWeights w = SigmaScheme::scaled(0.5, 2.0, 1.0).weights(4);
  CHECK_THAT(w.gamma, WithinRel(std::sqrt(1.25), 1e-15));
  CHECK_THAT(w.wm0, WithinRel(-2.75 / 1.25, 1e-15));
  CHECK_THAT(w.wc0, WithinRel(-2.75 / 1.25 + 1.0 - 0.25 + 2.0, 1e-15));
  CHECK_THAT(w.wi, WithinRel(1.0 / 2.5, 1e-15));
  CHECK_THAT(w.wm0 + 8 * w.wi, WithinAbs(1.0, 1e-14));
}

TEST_CASE("Huerta eqs. (49)-(52) weights", "[core][sigma]") {
  // L = 6, alpha = 0.8: lambda = 0.64*6 - 6 = -2.16; W0m = -2.16/3.84; W0c = W0m + 3 - 0.64.
  const SigmaWeights w = SigmaScheme::huerta(0.8).weights(6);
  CHECK_THAT(w.wm0, WithinRel(-2.16 / 3.84, 1e-14));
  CHECK_THAT(w.wc0, WithinRel(-2.16 / 3.84 + 3.0 - 0.64, 1e-14));
  CHECK_THAT(w.wi, WithinRel(1.0 / (2 * 3.84), 1e-14));
  CHECK_THAT(w.gamma * w.gamma, WithinRel(0.64 * 6, 1e-14));  // sqrt(alpha^2 L Q)
}

TEST_CASE("Julier and cubature weights", "[core][sigma]") {
  const SigmaWeights j = SigmaScheme::julier(2.0).weights(3);
  CHECK_THAT(j.wm0, WithinRel(0.4, 1e-15));
  CHECK_THAT(j.wi, WithinRel(0.1, 1e-15));
  CHECK_THAT(j.gamma, WithinRel(std::sqrt(5.0), 1e-15));
  const SigmaWeights c = SigmaScheme::cubature().weights(4);
  CHECK(c.wm0 == 0.0);
  CHECK_THAT(c.wi, WithinRel(0.125, 1e-15));
  CHECK_THAT(c.gamma, WithinRel(2.0, 1e-15));
}

TEST_CASE("sigma schemes reproduce mean and covariance", "[core][sigma]") {
  Vec<3> m(1.0, -2.0, 0.5);
  Mat<3, 3> P;
  P << 4, 1, 0.5, 1, 3, 0.2, 0.5, 0.2, 2;
  const Mat<3, 3> L = P.llt().matrixL();
  for (const auto& sch : {SigmaScheme::scaled(0.3, 2, 0), SigmaScheme::julier(1.0), SigmaScheme::cubature(),
                          SigmaScheme::huerta(0.9)}) {
    const SigmaWeights w = sch.weights(3);
    Mat<3, 7> X;
    sigma_points(m, L, w.gamma, X);
    Vec<3> mean = w.wm0 * X.col(0);
    for (int j = 1; j < 7; ++j) mean += w.wi * X.col(j);
    Mat<3, 3> C = w.wc0 * (X.col(0) - m) * (X.col(0) - m).transpose();  // zero: centre deviation
    for (int j = 1; j < 7; ++j) C += w.wi * (X.col(j) - m) * (X.col(j) - m).transpose();
    CHECK((mean - m).norm() < 1e-12);
    CHECK((C - P).norm() < 1e-12);
  }
}

TEST_CASE("sigma scheme rejects bad parameters", "[core][sigma]") {
  CHECK_THROWS_WITH(SigmaScheme::scaled(0.0).weights(4), Catch::Contains("alpha"));
  CHECK_THROWS_WITH(SigmaScheme::scaled(1.5).weights(4), Catch::Contains("alpha"));
  CHECK_THROWS_WITH(SigmaScheme::scaled(1.0, 2.0, -5.0).weights(4), Catch::Contains("kappa"));
  CHECK_THROWS_WITH(SigmaScheme::julier(-4.0).weights(4), Catch::Contains("kappa"));
  CHECK_THROWS_AS(SigmaScheme::scaled(std::nan("")).weights(4), std::invalid_argument);
  // eq. (52) has no kappa: -10 was refused and +10 silently ignored; both are refused now
  for (const double kappa : {-10.0, 10.0})
    CHECK_THROWS_WITH((SigmaScheme{SigmaScheme::Kind::kHuerta, 0.5, 2.0, kappa}.weights(4)),
                      Catch::StartsWith("sigma scheme: kappa: expected 0 for the Huerta rule (eq. 52)"));
  CHECK(SigmaScheme::huerta(0.5).weights(4).wi ==
        SigmaScheme{SigmaScheme::Kind::kScaled, 0.5, 2.0, 0.0}.weights(4).wi);
}

TEST_CASE("robust Cholesky reports its fallback", "[core][cholesky]") {
  Mat<2, 2> A;
  A << 4, 2, 2, 3;
  Mat<2, 2> L;
  REQUIRE(robust_cholesky(A, L) == CholeskyStatus::kOk);
  CHECK_THAT(L(0, 0), WithinRel(2.0, 1e-15));
  CHECK_THAT(L(1, 0), WithinRel(1.0, 1e-15));
  CHECK_THAT(L(1, 1), WithinRel(std::sqrt(2.0), 1e-15));
  // Rank-deficient PSD: plain LLT fails, jitter rescues it and says so.
  Mat<2, 2> B;
  B << 1, 1, 1, 1;
  double jit = 0.0;
  CHECK(robust_cholesky(B, L, &jit) == CholeskyStatus::kJittered);
  CHECK(jit > 0.0);
  CHECK(jit <= 1e-8);
  // Indefinite: reported as a failure, not patched.
  Mat<2, 2> C;
  C << 1, 0, 0, -1;
  CHECK(robust_cholesky(C, L) == CholeskyStatus::kFailed);
  CHECK_FALSE(is_spd(C));
  CHECK(is_spd(A));
  // 0 x 0 is positive definite (vacuously): Eigen's min/maxCoeff on it were undefined (a crash)
  const MatX E(0, 0);
  MatX LE(3, 3);
  CHECK(robust_cholesky(E, LE) == CholeskyStatus::kOk);
  CHECK(LE.size() == 0);
  CHECK(is_spd(E));
  CHECK(is_spsd(E));
  // the tolerance is checked: NaN passed a non-symmetric matrix, a negative one failed the identity
  Mat<2, 2> N;
  N << 2, 1, 0, 2;
  const Mat<2, 2> I = Mat<2, 2>::Identity();
  for (const double tol : {std::nan(""), -1.0, std::numeric_limits<double>::infinity()}) {
    CHECK_THROWS_WITH(is_spd(N, tol), Catch::StartsWith("rel_tol: expected a finite value >= 0, got "));
    CHECK_THROWS_WITH(is_spsd(I, tol), Catch::StartsWith("rel_tol: expected a finite value >= 0, got "));
  }
  CHECK_FALSE(is_spd(N));
  CHECK_FALSE(is_spsd(N, 0.1));
  CHECK(is_spsd(N, 0.5));  // asymmetry |1 - 0| = 1 <= 0.5 max|N|
}

TEST_CASE("log-sum-exp is exact and stable", "[core][logsumexp]") {
  Eigen::Vector3d v(1000.0, 1000.0, -std::numeric_limits<double>::infinity());
  CHECK_THAT(log_sum_exp(v), WithinRel(1000.0 + std::log(2.0), 1e-15));
  Eigen::Vector3d w(std::log(0.2), std::log(0.3), std::log(0.5));
  w.array() += 7.0;
  CHECK_THAT(log_normalize(w), WithinRel(7.0, 1e-14));
  CHECK_THAT(std::exp(w[1]), WithinRel(0.3, 1e-13));
  Eigen::Vector2d none(-INFINITY, -INFINITY);
  CHECK(log_sum_exp(none) == -std::numeric_limits<double>::infinity());
}

TEST_CASE("Gaussian log pdf from the Cholesky factor", "[core][logsumexp]") {
  Mat<2, 2> S;
  S << 2, 0.5, 0.5, 1;
  const Mat<2, 2> L = S.llt().matrixL();
  Vec<2> x(0.3, -0.7);
  const double q = x.dot(S.inverse() * x);
  const double ref = -0.5 * (2 * std::log(2 * kPi) + std::log(S.determinant()) + q);
  CHECK_THAT(gaussian_log_pdf_chol(L, x), WithinRel(ref, 1e-13));
}

TEST_CASE("Rng is reproducible and has the right moments", "[core][random]") {
  Rng a(42, 3), b(42, 3), c(42, 4);
  CHECK(a() == b());
  CHECK(a() != c());
  Rng r(7);
  const int n = 200000;
  double s = 0, s2 = 0, u = 0;
  for (int i = 0; i < n; ++i) {
    const double z = r.normal();
    s += z;
    s2 += z * z;
    u += r.uniform();
  }
  CHECK(std::abs(s / n) < 5.0 / std::sqrt(n));
  CHECK(std::abs(s2 / n - 1.0) < 5.0 * std::sqrt(2.0 / n));
  CHECK(std::abs(u / n - 0.5) < 5.0 * std::sqrt(1.0 / 12.0 / n));
  for (int i = 0; i < 1000; ++i) CHECK(r.below(7) < 7);
}

TEST_CASE("wrap_angle maps to the half-open interval from -pi to pi", "[core]") {
  CHECK_THAT(wrap_angle(3 * kPi), WithinAbs(kPi, 1e-12));
  CHECK_THAT(wrap_angle(-kPi), WithinAbs(kPi, 1e-12));
  CHECK_THAT(wrap_angle(0.1 - 2 * kPi), WithinAbs(0.1, 1e-12));
}

TEST_CASE("Gaussian::validate names the argument", "[core]") {
  Gaussian<2> g;
  g.cov << 1, 2, 2, 1;  // indefinite
  CHECK_THROWS_WITH(g.validate("initial"), Catch::Contains("initial.cov"));
  g.cov.setIdentity();
  g.mean[0] = NAN;
  CHECK_THROWS_WITH(g.validate("initial"), Catch::Contains("initial.mean"));
}
