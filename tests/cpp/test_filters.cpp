// KF, EKF, UKF (additive and augmented): agreement on linear models, missing rows, accuracy on a seeded
// TOA track, log-likelihood by hand, and the state left unchanged by rejected calls.
#include <catch2/catch.hpp>

#include "nlosloc/core/random.hpp"
#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"

using namespace nlosloc;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
namespace nn = nlosloc::noise;

template class nlosloc::Kf<ConstantVelocity2>;
template class nlosloc::Ekf<ConstantVelocity2>;
template class nlosloc::Ukf<ConstantVelocity2>;
template class nlosloc::UkfAugmented<ConstantVelocity2>;
template class nlosloc::Ukf<TwoWayClock>;
template class nlosloc::UkfAugmented<ConstantVelocityClock2>;

namespace {
Gaussian<4> initial4() {
  Gaussian<4> g;
  g.mean << 10, -5, 1, 0.5;
  g.cov = Vec<4>(100, 80, 4, 3).asDiagonal();
  g.cov(0, 1) = g.cov(1, 0) = 10;
  return g;
}
MatX linear_H() {
  MatX H(3, 4);
  H << 1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0.5, 0;
  return H;
}
MeasurementStack linear_stack(const Eigen::Vector3d& sd) {
  MatX anchors(1, 2);
  anchors << 0, 0;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 1);
  const MatX H = linear_H();
  for (int i = 0; i < 3; ++i) st.add_linear(H.row(i).transpose(), -1, {nn::Normal(0.0, sd[i])});
  return st;
}
MeasurementStack toa_stack(int conditions = 1) {
  MatX anchors(3, 2);
  anchors << 0, 0, 8600, 0, 4300, 7500;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, conditions);
  for (int b = 0; b < 3; ++b) {
    std::vector<noise::Distribution> n{nn::Normal(0, 50)};
    if (conditions == 2) n.push_back(nn::ShiftedNormal(513, 436));
    st.add_toa(b, n);
  }
  return st;
}
}  // namespace

TEST_CASE("KF, UKF and augmented UKF agree on a linear model", "[filters][kf][ukf]") {
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  const Eigen::Vector3d sd(2.0, 3.0, 1.5);
  Kf<ConstantVelocity2> kf(motion, linear_H(), Eigen::Vector3d(4, 9, 2.25).asDiagonal().toDenseMatrix(),
                           initial4());
  Ukf<ConstantVelocity2> ukf(motion, linear_stack(sd), initial4(), SigmaScheme::scaled(0.5, 2, 0));
  UkfAugmented<ConstantVelocity2> aug(motion, linear_stack(sd), initial4(), SigmaScheme::scaled(0.7, 2, 0));
  Ukf<ConstantVelocity2> cub(motion, linear_stack(sd), initial4(), SigmaScheme::cubature());
  Rng rng(11);
  Vec<4> x = initial4().mean;
  for (int k = 0; k < 200; ++k) {
    x = motion.F() * x;
    VecX y = linear_H() * x;
    for (int i = 0; i < 3; ++i) y[i] += sd[i] * rng.normal();
    if (k % 17 == 5) y[1] = NAN;  // missing rows are skipped identically
    const StepResult a = kf.step(y), b = ukf.step(y), c = aug.step(y), d = cub.step(y);
    REQUIRE((kf.mean() - ukf.mean()).norm() < 1e-9 * (1 + kf.mean().norm()));
    REQUIRE((kf.cov() - ukf.cov()).norm() < 1e-9 * kf.cov().norm());
    REQUIRE((kf.mean() - aug.mean()).norm() < 1e-9 * (1 + kf.mean().norm()));
    REQUIRE((kf.cov() - aug.cov()).norm() < 1e-9 * kf.cov().norm());
    REQUIRE((kf.mean() - cub.mean()).norm() < 1e-9 * (1 + kf.mean().norm()));
    REQUIRE_THAT(a.log_likelihood, WithinAbs(b.log_likelihood, 1e-9));
    REQUIRE_THAT(a.log_likelihood, WithinAbs(c.log_likelihood, 1e-9));
    REQUIRE_THAT(a.log_likelihood, WithinAbs(d.log_likelihood, 1e-9));
    REQUIRE(a.rows_used == (k % 17 == 5 ? 2 : 3));
  }
}

TEST_CASE("KF update and log-likelihood by hand", "[filters][kf]") {
  const ConstantVelocity2 motion(1.0, 0.0);
  MatX H(1, 4);
  H << 1, 0, 0, 0;
  MatX R(1, 1);
  R << 4.0;
  Gaussian<4> g;
  g.mean << 0, 0, 1, 0;
  g.cov = Vec<4>(5, 5, 1, 1).asDiagonal();
  Kf<ConstantVelocity2> kf(motion, H, R, g);
  VecX y(1);
  y << 4.0;
  const StepResult r = kf.step(y);
  // Prior x = 1, var = 5 + 1 (velocity) = 6; S = 10; K = 0.6; x+ = 1 + 0.6*3 = 2.8; var+ = 2.4.
  CHECK_THAT(kf.mean()[0], WithinRel(2.8, 1e-14));
  CHECK_THAT(kf.cov()(0, 0), WithinRel(2.4, 1e-14));
  CHECK_THAT(r.log_likelihood, WithinRel(-0.5 * (std::log(2 * kPi * 10) + 9.0 / 10), 1e-14));
  CHECK(kf.time() == 1.0);
}

TEST_CASE("a NaN row is the same as leaving the row out", "[filters][missing]") {
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  MeasurementStack full = toa_stack();
  MatX anchors(2, 2);
  anchors << 0, 0, 4300, 7500;
  MeasurementStack part(ConstantVelocity2::layout(), anchors, 1);
  part.add_toa(0, {nn::Normal(0, 50)}).add_toa(1, {nn::Normal(0, 50)});
  Gaussian<4> g;
  g.mean << 1000, 1000, 10, 15;
  g.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  Ukf<ConstantVelocity2> a(motion, full, g, SigmaScheme::scaled(0.5)),
      b(motion, part, g, SigmaScheme::scaled(0.5));
  Ekf<ConstantVelocity2> c(motion, full, g), d(motion, part, g);
  VecX y3(3), y2(2);
  y3 << 1420, NAN, 6700;
  y2 << 1420, 6700;
  const StepResult ra = a.step(y3), rb = b.step(y2), rc = c.step(y3), rd = d.step(y2);
  CHECK((a.mean() - b.mean()).norm() < 1e-9);
  CHECK((a.cov() - b.cov()).norm() < 1e-9);
  CHECK_THAT(ra.log_likelihood, WithinAbs(rb.log_likelihood, 1e-12));
  CHECK((c.mean() - d.mean()).norm() < 1e-9);
  CHECK_THAT(rc.log_likelihood, WithinAbs(rd.log_likelihood, 1e-12));
  CHECK(ra.rows_used == 2);
  // The augmented UKF leaves the missing row's noise input out of the set (n + q_a = 6, not 7): with it
  // the cubature points of the other rows spread by sqrt(7) instead of sqrt(6) (0.012 m apart in 5 steps).
  for (const SigmaScheme& sc : {SigmaScheme::scaled(0.5), SigmaScheme::cubature()}) {
    UkfAugmented<ConstantVelocity2> e(motion, full, g, sc), f(motion, part, g, sc);
    for (int k = 0; k < 5; ++k) {
      const StepResult re = e.step(y3), rf = f.step(y2);
      CHECK_THAT(re.log_likelihood, WithinRel(rf.log_likelihood, 1e-12));
      CHECK(re.rows_used == 2);
    }
    CHECK((e.mean() - f.mean()).norm() < 1e-9);
    CHECK((e.cov() - f.cov()).norm() < 1e-7);
    CHECK(e.augmented_dim() == 7);
  }
  // All rows missing: a pure prediction.
  VecX none = VecX::Constant(3, NAN);
  const Vec<4> before = motion.F() * a.mean();
  const StepResult rn = a.step(none);
  CHECK(rn.rows_used == 0);
  CHECK(rn.log_likelihood == 0.0);
  CHECK((a.mean() - before).norm() < 1e-12);
}

TEST_CASE("EKF and UKF track a TOA constant-velocity target (seeded)", "[filters][accuracy]") {
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  const MeasurementStack st = toa_stack();
  Rng rng(2024);
  Vec<4> x(1000, 1000, 10, 15);
  Gaussian<4> g;
  g.mean = x + Vec<4>(50 * rng.normal(), 50 * rng.normal(), 0, 0);
  g.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  Ekf<ConstantVelocity2> ekf(motion, st, g);
  Ukf<ConstantVelocity2> ukf(motion, st, g, SigmaScheme::scaled(1.0, 2.0, 0.0));
  UkfAugmented<ConstantVelocity2> aug(motion, st, g, SigmaScheme::scaled(1.0, 2.0, 0.0));
  const Mat<4, 4> Lq = motion.Q().llt().matrixL();
  double se_e = 0, se_u = 0, se_a = 0;
  int n = 0;
  VecX y(3);
  for (int k = 0; k < 1000; ++k) {
    x = motion.F() * x + Lq * Vec<4>(rng.normal(), rng.normal(), rng.normal(), rng.normal());
    st.predict(x, 0, y);
    for (int i = 0; i < 3; ++i) y[i] += 50 * rng.normal();
    ekf.step(y);
    ukf.step(y);
    aug.step(y);
    if (k >= 100) {
      se_e += (ekf.mean().head<2>() - x.head<2>()).squaredNorm();
      se_u += (ukf.mean().head<2>() - x.head<2>()).squaredNorm();
      se_a += (aug.mean().head<2>() - x.head<2>()).squaredNorm();
      ++n;
    }
  }
  // 50 m ranges from ~4-8 km with a smooth track: the position RMSE settles near 10-20 m.
  INFO("rmse ekf " << std::sqrt(se_e / n) << " ukf " << std::sqrt(se_u / n) << " aug "
                   << std::sqrt(se_a / n));
  CHECK(std::sqrt(se_e / n) < 25.0);
  CHECK(std::sqrt(se_u / n) < 25.0);
  CHECK(std::abs(std::sqrt(se_u / n) - std::sqrt(se_a / n)) < 1.0);
}

TEST_CASE("the sight vector selects each row's noise", "[filters][sight]") {
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  Gaussian<4> g;
  g.mean << 1000, 1000, 10, 15;
  g.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  Ukf<ConstantVelocity2> a(motion, toa_stack(2), g), b(motion, toa_stack(2), g);
  VecX y(3);
  toa_stack().predict(Vec<4>(1001, 1001.5, 10, 15), 0.1, y);
  y[1] += 513;
  VecXi s(3);
  s << 0, 1, 0;
  a.step(y);  // all LOS: the biased row pulls the estimate
  b.step(y, s);
  Vec<2> truth(1001, 1001.5);
  CHECK((b.mean().head<2>() - truth).norm() < (a.mean().head<2>() - truth).norm());
  CHECK((b.mean().head<2>() - truth).norm() < 20.0);
}

TEST_CASE("rejected calls leave the filter unchanged", "[filters][errors]") {
  const ConstantVelocity2 motion(0.1, 1.0);
  Ukf<ConstantVelocity2> f(motion, toa_stack(2), initial4());
  Ekf<ConstantVelocity2> e(motion, toa_stack(2), initial4());
  const Vec<4> x0 = f.mean();
  const Mat<4, 4> P0 = f.cov();
  const double t0 = f.time();
  auto unchanged = [&] {
    CHECK(f.mean() == x0);
    CHECK(f.cov() == P0);
    CHECK(f.time() == t0);
  };
  CHECK_THROWS_WITH(f.step(VecX::Zero(2)), Catch::Contains("y: expected shape (3, 1), got (2, 1)"));
  unchanged();
  VecX yi(3);
  yi << 1, INFINITY, 2;
  CHECK_THROWS_WITH(f.step(yi), Catch::Contains("got inf at row 1"));
  unchanged();
  VecXi bad(3);
  bad << 0, 2, 0;
  CHECK_THROWS_WITH(f.step(VecX::Zero(3), bad), Catch::Contains("sight: expected conditions in [0, 2)"));
  unchanged();
  CHECK_THROWS_WITH(f.step(VecX::Zero(3), VecXi::Zero(2)), Catch::Contains("sight: expected shape"));
  unchanged();
  CHECK_THROWS_WITH(e.update(VecX::Zero(4)), Catch::Contains("y: expected shape"));
  CHECK(e.mean() == x0);
  Gaussian<4> np = initial4();
  np.cov(0, 0) = -1;
  CHECK_THROWS_WITH(f.set_belief(np), Catch::Contains("belief.cov: expected a symmetric positive definite"));
  unchanged();
  CHECK_THROWS_WITH(Ukf<ConstantVelocity2>(motion, toa_stack(), np), Catch::Contains("initial.cov"));
  CHECK_THROWS_WITH(Ukf<ConstantVelocity2>(motion, toa_stack(), initial4(), SigmaScheme::scaled(2.0)),
                    Catch::Contains("alpha"));
  MatX anchors(1, 2);
  anchors << 0, 0;
  MeasurementStack clock(ConstantVelocityClock2::layout(), anchors, 1);
  clock.add_rtoa(0, {nn::Normal(0, 1)});
  CHECK_THROWS_WITH(Ukf<ConstantVelocity2>(motion, clock, initial4()), Catch::Contains("layout dimension 6"));
  MeasurementStack empty(ConstantVelocity2::layout(), anchors, 1);
  CHECK_THROWS_WITH(Ekf<ConstantVelocity2>(motion, empty, initial4()), Catch::Contains("no rows"));
  MatX H = linear_H();
  CHECK_THROWS_WITH(Kf<ConstantVelocity2>(motion, H, MatX::Identity(2, 2), initial4()),
                    Catch::Contains("R: expected shape"));
  CHECK_THROWS_WITH(Kf<ConstantVelocity2>(motion, H, -MatX::Identity(3, 3), initial4()),
                    Catch::Contains("R: expected a symmetric positive definite"));
}

TEST_CASE("augmented UKF uses the exact two-way-ranging noise", "[filters][ukf][twr]") {
  // One exchange per step with 4 anchors; the tracker should lock on to skew/offset and position.
  const TwoWayClock motion(1e-3, 1e-11, 1e-11, 0.1);
  MatX anchors(4, 2);
  anchors << 100, 0, 0, 100, -100, 0, 0, -100;
  MeasurementStack st(TwoWayClock::layout(), anchors, 1);
  for (int b = 0; b < 4; ++b) st.add_twr(b, b, 5e-6, 1e-6, 0.2e-9, {std::nullopt});
  Vec<6> x;
  x << 1 - 1e-5, 500e-9, 0, 0, 0, 0;
  Gaussian<6> g;
  g.mean = x;
  g.mean[0] += 1e-6;  // one prior std off, so the skew must be tracked, not merely kept
  g.mean[4] += 0.3;
  g.mean[5] -= 0.2;
  g.cov = Vec<6>(1e-12, 1e-14, 0.01, 0.01, 1, 1).asDiagonal();
  UkfAugmented<TwoWayClock> f(motion, st, g, SigmaScheme::scaled(1.0, 2.0, 0.0));
  Rng rng(3);
  VecX y(8), u(st.noise_dim());
  VecXi s = VecXi::Zero(4);
  for (int k = 0; k < 300; ++k) {
    x = motion.F() * x;
    for (int j = 0; j < u.size(); ++j) u[j] = rng.normal();
    st.predict_augmented(x, f.time() + motion.dt(), u, s, y);
    f.step(y);
  }
  CHECK((f.mean().tail<2>() - x.tail<2>()).norm() < 0.1);
  CHECK_THAT(f.mean()[0], WithinAbs(x[0], 1e-8));

  // A missing pair (both rows of anchor 3) leaves its five inputs out; a missing T row (eq. 20) only n^C
  // and n^D, which its tau row (eq. 17) does not read: each equals the filter on a stack without them.
  MeasurementStack three(TwoWayClock::layout(), anchors.topRows(3), 1);
  for (int b = 0; b < 3; ++b) three.add_twr(b, b, 5e-6, 1e-6, 0.2e-9, {std::nullopt});
  UkfAugmented<TwoWayClock> h(motion, st, g, SigmaScheme::scaled(1.0, 2.0, 0.0)),
      h3(motion, three, g, SigmaScheme::scaled(1.0, 2.0, 0.0));
  x = g.mean;
  for (int k = 0; k < 20; ++k) {
    x = motion.F() * x;
    for (int j = 0; j < u.size(); ++j) u[j] = rng.normal();
    st.predict_augmented(x, h.time() + motion.dt(), u, s, y);
    VecX y8 = y;
    y8.tail<2>().setConstant(NAN);
    const StepResult r8 = h.step(y8), r6 = h3.step(y.head<6>());
    CHECK_THAT(r8.log_likelihood, WithinRel(r6.log_likelihood, 1e-10));
  }
  CHECK(((h.mean() - h3.mean()).array().abs() <= 1e-9 * h3.mean().array().abs() + 1e-15).all());
  // Which inputs stay: the T row of anchor 0 missing drops n^C and n^D of its pair (18 of 20 stay); its
  // tau row missing drops none, since the T row reads all five.
  detail::AugmentedMoments<6> mom;
  const SigmaScheme sc = SigmaScheme::cubature();
  mom.resize(8, st.noise_dim(), sc);
  VecX zhat(8), yt = y;
  MatX S(8, 8);
  Eigen::Matrix<double, 6, Eigen::Dynamic> Pxz(6, 8);
  const Mat<6, 6> L = h.cov().llt().matrixL();
  const auto inputs_with = [&](int missing) {
    yt = y;
    if (missing >= 0) yt[missing] = NAN;
    mom.compute(st, h.mean(), L, sc.weights(6 + 20), h.time(), s, zhat, S, Pxz, &yt);
    return mom.active_inputs();
  };
  CHECK(inputs_with(-1) == 20);
  CHECK(inputs_with(1) == 18);
  CHECK(inputs_with(0) == 20);
  CHECK(inputs_with(7) == 18);
}
