// Motion and measurement models: matrices and predictions by hand, Jacobians against finite differences,
// noise moments against simulation, and argument checks.
#include <catch2/catch.hpp>
#include <limits>

#include "nlosloc/core/random.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"

using namespace nlosloc;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
namespace nn = nlosloc::noise;

template class nlosloc::ConstantVelocity<2>;
template class nlosloc::ConstantVelocity<3>;
template class nlosloc::ConstantVelocityClock<2>;
template class nlosloc::ConstantVelocityClock<3>;

TEST_CASE("constant velocity F and Q (Huerta eqs. 6-7, Ke and Wu eq. 16)", "[models][motion]") {
  const ConstantVelocity2 rw(0.1, 2.0, VelocityNoise::kRandomWalk);
  CHECK(rw.F()(0, 2) == 0.1);
  CHECK(rw.F()(1, 3) == 0.1);
  CHECK(rw.F()(0, 0) == 1.0);
  CHECK(rw.F()(2, 0) == 0.0);
  CHECK_THAT(rw.Q()(2, 2), WithinRel(0.2, 1e-15));  // dt sigma_v^2
  CHECK(rw.Q()(0, 0) == 0.0);
  CHECK(rw.Q()(0, 2) == 0.0);
  const ConstantVelocity2 wa(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  // G = [dt^2/2; dt] per axis: Q = [[dt^4/4, dt^3/2], [dt^3/2, dt^2]].
  CHECK_THAT(wa.Q()(0, 0), WithinRel(2.5e-5, 1e-12));
  CHECK_THAT(wa.Q()(0, 2), WithinRel(5e-4, 1e-12));
  CHECK_THAT(wa.Q()(2, 2), WithinRel(1e-2, 1e-12));
  CHECK(wa.Q()(0, 1) == 0.0);
  const ConstantVelocity3 cv3(0.5, 1.0);
  CHECK(cv3.F()(2, 5) == 0.5);
  CHECK(ConstantVelocity3::layout().velocity == 3);
  CHECK_THROWS_WITH(ConstantVelocity2(0.0, 1.0), Catch::Contains("dt"));
  CHECK_THROWS_WITH(ConstantVelocity2(0.1, -1.0), Catch::Contains("sigma2"));
}

TEST_CASE("constant velocity with clock (Huerta eq. 5)", "[models][motion]") {
  const ConstantVelocityClock2 m(0.01, 1.0, 1e-2);
  // state [x, y, tau, vx, vy, taudot]
  CHECK(m.F()(2, 5) == 0.01);
  CHECK(m.F()(0, 3) == 0.01);
  CHECK_THAT(m.Q()(3, 3), WithinRel(0.01, 1e-15));
  CHECK_THAT(m.Q()(5, 5), WithinRel(1e-4, 1e-15));
  CHECK(m.Q()(2, 2) == 0.0);
  const StateLayout l = ConstantVelocityClock2::layout();
  CHECK(l.clock_bias == 2);
  CHECK(l.velocity == 3);
  CHECK(l.clock_drift == 5);
  CHECK_THROWS_WITH(ConstantVelocityClock2(0.01, 1.0, -1.0), Catch::Contains("sigma_tau2"));
}

TEST_CASE("two-way clock model (Grisales eqs. 14-15)", "[models][motion]") {
  const TwoWayClock m(1e-3, 1e-11, 1e-11, 0.1);
  CHECK(m.F()(4, 2) == 1e-3);
  CHECK(m.F()(5, 3) == 1e-3);
  CHECK(m.F()(4, 4) == 1.0);
  CHECK_THAT(m.Q()(0, 0), WithinRel(1e-22, 1e-12));
  CHECK_THAT(m.Q()(2, 2), WithinRel(0.01, 1e-12));
  CHECK(m.Q()(4, 4) == 0.0);
  CHECK_THROWS_WITH(TwoWayClock(0.0, 1, 1, 1), Catch::Contains("h"));
}

namespace {
std::vector<noise::Distribution> two(double s1, double s2) {
  return {nn::Normal(0.0, s1), nn::Normal(0.0, s2)};
}

/// Central finite differences of g against the analytic Jacobian (the property suite of every row type).
template <int N>
void check_jacobians(const MeasurementStack& st, const Vec<N>& x, double t, double rel_step = 1e-6) {
  const int m = st.rows();
  Eigen::Matrix<double, Eigen::Dynamic, N> J(m, N), Jn(m, N);
  st.jacobian(x, t, J);
  VecX yp(m), ym(m);
  for (int k = 0; k < N; ++k) {
    const double h = rel_step * std::max(1.0, std::abs(x[k]));
    Vec<N> xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    st.predict(xp, t, yp);
    st.predict(xm, t, ym);
    VecX d = yp - ym;
    st.wrap_residual(d);
    Jn.col(k) = d / (2 * h);
  }
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < N; ++k) {
      INFO("row " << i << " (" << to_string(st.row(i).kind) << ") col " << k);
      CHECK_THAT(J(i, k), WithinAbs(Jn(i, k), 1e-6 * std::max(1.0, std::abs(Jn(i, k)))));
    }
}
}  // namespace

TEST_CASE("TOA, TDOA, AOA predictions by hand", "[models][measurement]") {
  MatX anchors(3, 2);
  anchors << 0, 0, 6, 0, 0, 8;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 2);
  st.add_toa(0, two(1, 2)).add_tdoa(1, 2, two(1, 2), two(1, 3)).add_aoa(0, two(0.1, 0.2));
  st.add_aoa_phase(1, kPi / 2, two(0.1, 0.2));
  Vec<4> x(3, 4, 1, 1);
  VecX y(4);
  st.predict(x, 0.0, y);
  CHECK_THAT(y[0], WithinRel(5.0, 1e-15));        // ||(3,4)||
  CHECK_THAT(y[1], WithinRel(5.0 - 5.0, 1e-15));  // ||(-3,4)|| - ||(3,-4)||
  CHECK_THAT(y[2], WithinRel(std::atan2(4.0, 3.0), 1e-15));
  CHECK_THAT(y[3], WithinRel(kPi * std::sin(std::atan2(4.0, -3.0) - kPi / 2), 1e-14));
  CHECK(st.noise_dim() == 5);  // 1 + 2 + 1 + 1
  CHECK(st.has_angles());
  // Noise moments under sight (1, 0, 1): TOA NLOS var 4; TDOA n_1 - n_2 with anchor 1 LOS, anchor 2 NLOS.
  VecXi s(3);
  s << 1, 0, 1;
  VecX mean(4);
  MatX R(4, 4);
  st.noise_moments(x, s, mean, R);
  CHECK(R(0, 0) == 4.0);
  CHECK_THAT(R(1, 1), WithinRel(1.0 + 9.0, 1e-15));
  CHECK_THAT(R(2, 2), WithinRel(0.04, 1e-15));
  CHECK(R(0, 1) == 0.0);
  CHECK(mean.norm() == 0.0);
  // An asymmetric point, so the TDOA's sign shows: ||(1,1) - q_1|| - ||(1,1) - q_2|| = sqrt(26) - sqrt(50).
  st.predict(Vec<4>(1, 1, 0, 0), 0.0, y);
  CHECK_THAT(y[1], WithinRel(std::sqrt(26.0) - std::sqrt(50.0), 1e-15));
}

TEST_CASE("TDOA noise is n_a - n_b: NLOS means and medians subtract", "[models][measurement]") {
  MatX a(2, 2);
  a << 0, 0, 100, 0;
  MeasurementStack st(ConstantVelocity2::layout(), a, 2);
  st.add_tdoa(0, 1, {nn::Normal(0, 1), nn::ShiftedNormal(500, 40)},
              {nn::Normal(0, 2), nn::ShiftedNormal(200, 30)});
  const Vec<4> x(30, 40, 0, 0);
  VecX mean(1), y(1), ya(1), u = VecX::Zero(2);
  MatX R(1, 1);
  VecXi s(2);
  s << 1, 0;  // anchor a NLOS, b LOS: mean +500
  st.noise_moments(x, s, mean, R);
  CHECK(mean[0] == 500.0);
  CHECK_THAT(R(0, 0), WithinRel(1600.0 + 4.0, 1e-15));
  s << 0, 1;  // a LOS, b NLOS: mean -200
  st.noise_moments(x, s, mean, R);
  CHECK(mean[0] == -200.0);
  s << 1, 1;
  st.noise_moments(x, s, mean, R);
  CHECK(mean[0] == 300.0);
  CHECK_THAT(R(0, 0), WithinRel(1600.0 + 900.0, 1e-15));
  // Augmented prediction with u = 0: g(x) + median_a - median_b (Huerta Table III.1 with a TDOA row).
  st.predict(x, 0, y);
  st.predict_augmented(x, 0, u, s, ya);
  CHECK_THAT(ya[0], WithinRel(y[0] + 500.0 - 200.0, 1e-14));
}

TEST_CASE("angle residuals wrap", "[models][measurement]") {
  MatX anchors(1, 2);
  anchors << 0, 0;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 1);
  st.add_toa(0, {nn::Normal(0, 1)}).add_aoa(0, {nn::Normal(0, 0.1)});
  VecX r(2);
  r << 2 * kPi + 0.5, 2 * kPi - 0.1;
  st.wrap_residual(r);
  CHECK_THAT(r[0], WithinRel(2 * kPi + 0.5, 1e-15));  // TOA untouched
  CHECK_THAT(r[1], WithinAbs(-0.1, 1e-12));
}

TEST_CASE("Jacobians match finite differences for every row type", "[models][measurement][jacobian]") {
  MatX a2(4, 2);
  a2 << 0, 0, 100, 10, 30, 120, -50, 60;
  {
    MeasurementStack st(ConstantVelocity2::layout(), a2, 2);
    st.add_toa(0, two(1, 2)).add_tdoa(1, 3, two(1, 2), two(1, 2)).add_aoa(2, two(0.1, 0.2));
    st.add_aoa_phase(3, 0.3, two(0.1, 0.2));
    VecX h(4);
    h << 1, -2, 0.5, 3;
    st.add_linear(h, -1, two(1, 1));
    check_jacobians<4>(st, Vec<4>(20, 35, 1, -2), 0.0);
    check_jacobians<4>(st, Vec<4>(-80, 5, 1, -2), 0.0);  // AOA near the +-pi cut of anchor 0
  }
  {
    MeasurementStack st(ConstantVelocityClock2::layout(), a2, 2);
    for (int b = 0; b < 4; ++b) st.add_rtoa(b, two(1, 2));
    Vec<6> x;
    x << 20, 35, 4.5, 1, -2, 0.1;
    check_jacobians<6>(st, x, 0.0);
  }
  {
    MatX a3(3, 3);
    a3 << 0, 0, 0, 100, 0, 10, 0, 100, 30;
    MeasurementStack st(ConstantVelocity3::layout(), a3, 1);
    for (int b = 0; b < 3; ++b) st.add_toa(b, {nn::Normal(0, 1)});
    st.add_tdoa(0, 2, {nn::Normal(0, 1)}, {nn::Normal(0, 1)});
    Vec<6> x;
    x << 10, 20, 5, 1, 1, 1;
    check_jacobians<6>(st, x, 0.0);
  }
  {
    MeasurementStack st(TwoWayClock::layout(), a2, 2);
    for (int b = 0; b < 4; ++b)
      st.add_twr(b, b, 5e-6, 1e-6, 0.2e-9, {std::nullopt, nn::Normal(0.35e-9, 0.07e-9)});
    Vec<6> x;
    x << 1 - 1e-5, 500e-9, 0.5, -0.2, 20, 35;
    check_jacobians<6>(st, x, 0.123, 1e-7);
  }
}

TEST_CASE("two-way ranging: eqs. (17)-(20) by hand and exact noise moments", "[models][measurement][twr]") {
  MatX a(1, 2);
  a << 30, 40;  // 50 m from the origin
  MeasurementStack st(TwoWayClock::layout(), a, 2);
  const double Delta = 5e-6, delta = 1e-6, sm = 0.2e-9;
  st.add_twr(0, 2, Delta, delta, sm, {std::nullopt, nn::Normal(8.5e-9, 2e-9)});
  REQUIRE(st.rows() == 2);
  REQUIRE(st.noise_dim() == 5);
  Vec<6> x;
  x << 1 - 1e-5, 500e-9, 0, 0, 0, 0;
  const double t = 0.01, om = x[0], dc = 50.0 / kSpeedOfLight;
  VecX y(2);
  st.predict(x, t, y);
  CHECK_THAT(y[0], WithinRel(om * (t + 2 * Delta + dc) + 500e-9, 1e-14));   // eq. (22)
  CHECK_THAT(y[1], WithinRel(dc + 0.5 * delta * (1.0 / om - 1.0), 1e-12));  // eq. (23)
  // Moments of y - g(x) under NLOS against 400k simulated noises through predict_augmented.
  VecXi s(1);
  s << 1;
  VecX mean(2);
  MatX R(2, 2);
  st.noise_moments(x, s, mean, R);
  Rng rng(5);
  const int n = 400000;
  Eigen::Vector2d acc = Eigen::Vector2d::Zero();
  Eigen::Matrix2d acc2 = Eigen::Matrix2d::Zero();
  VecX u(5), ya(2);
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < 5; ++j) u[j] = rng.normal();
    st.predict_augmented(x, t, u, s, ya);
    const Eigen::Vector2d e = ya - y;
    acc += e;
    acc2 += e * e.transpose();
  }
  acc /= n;
  acc2 = acc2 / n - acc * acc.transpose();
  CHECK_THAT(acc[0], WithinAbs(mean[0], 5 * std::sqrt(R(0, 0) / n)));
  CHECK_THAT(acc[1], WithinAbs(mean[1], 5 * std::sqrt(R(1, 1) / n)));
  CHECK_THAT(acc2(0, 0), WithinRel(R(0, 0), 0.02));
  CHECK_THAT(acc2(1, 1), WithinRel(R(1, 1), 0.02));
  CHECK_THAT(acc2(0, 1), WithinRel(R(0, 1), 0.02));
  // Hand values: var tau = om^2 (s^2 + vG) + s^2, var T = vG + 2 s^2 + 2 s^2/om^2.
  const double s2 = sm * sm, vG = 4e-18;
  CHECK_THAT(R(0, 0), WithinRel(om * om * (s2 + vG) + s2, 1e-12));
  CHECK_THAT(R(1, 1), WithinRel(vG + 2 * s2 + 2 * s2 / (om * om), 1e-12));
}

TEST_CASE("augmented prediction with u = 0 is g(x) plus the noise medians", "[models][measurement]") {
  MatX a(2, 2);
  a << 0, 0, 100, 0;
  MeasurementStack st(ConstantVelocity2::layout(), a, 2);
  st.add_toa(0, {nn::Normal(0, 1), nn::ShiftedNormal(500, 40)}).add_toa(1, two(1, 1));
  Vec<4> x(30, 40, 0, 0);
  VecX y(2), ya(2), u = VecX::Zero(2);
  VecXi s(2);
  s << 1, 0;
  st.predict(x, 0, y);
  st.predict_augmented(x, 0, u, s, ya);
  CHECK_THAT(ya[0], WithinRel(y[0] + 500.0, 1e-14));
  CHECK_THAT(ya[1], WithinRel(y[1], 1e-14));
}

TEST_CASE("measurement stack rejects bad input with named arguments", "[models][measurement][errors]") {
  MatX a(2, 2);
  a << 0, 0, 1, 1;
  MatX bad = a;
  bad(1, 0) = NAN;
  CHECK_THROWS_WITH(MeasurementStack(ConstantVelocity2::layout(), bad, 2), Catch::Contains("anchors"));
  CHECK_THROWS_WITH(MeasurementStack(ConstantVelocity2::layout(), MatX::Zero(2, 3), 2),
                    Catch::Contains("anchors: expected shape"));
  CHECK_THROWS_WITH(MeasurementStack(ConstantVelocity2::layout(), a, 0), Catch::Contains("num_conditions"));
  MeasurementStack st(ConstantVelocity2::layout(), a, 2);
  CHECK_THROWS_WITH(st.add_toa(2, two(1, 1)), Catch::Contains("add_toa: anchor"));
  CHECK_THROWS_WITH(st.add_toa(0, {nn::Normal(0, 1)}), Catch::Contains("add_toa: noise"));
  CHECK_THROWS_WITH(st.add_rtoa(0, two(1, 1)), Catch::Contains("clock bias"));
  CHECK_THROWS_WITH(st.add_tdoa(0, 0, two(1, 1), two(1, 1)), Catch::Contains("differ"));
  CHECK_THROWS_WITH(st.add_twr(0, 0, 1e-6, 1e-6, 1e-9, {std::nullopt, std::nullopt}),
                    Catch::Contains("skew"));
  CHECK(st.rows() == 0);  // rejected calls add nothing
  VecXi s(2);
  s << 0, 2;
  CHECK_THROWS_WITH(st.check_sight(s), Catch::Contains("sight"));
  // Row queries check the index (std::out_of_range: IndexError in Python) and name it.
  st.add_toa(0, two(1, 1));
  CHECK_THROWS_AS(st.row(1), std::out_of_range);
  CHECK_THROWS_WITH(st.row(1), "i: expected a row index in [0, 1), got 1");
  CHECK_THROWS_WITH(st.is_angle(-1), "i: expected a row index in [0, 1), got -1");
  CHECK_THROWS_WITH(st.noise(0, 2), "condition: expected a sight condition in [0, 2), got 2");
  CHECK(st.noise(0, 1).variance() == 1.0);
}

TEST_CASE("motion models refuse parameters whose F or Q overflows", "[models][motion][errors]") {
  CHECK_THROWS_WITH(ConstantVelocity2(10.0, 1e308),
                    Catch::Matchers::StartsWith("dt, sigma2: the transition F or process noise Q overflows"));
  CHECK_THROWS_WITH(ConstantVelocity2(1e80, 1.0, VelocityNoise::kWhiteAcceleration),
                    Catch::Matchers::StartsWith("dt, sigma2: the transition F or process noise Q overflows"));
  CHECK_THROWS_WITH(ConstantVelocityClock2(1.0, 1.0, std::numeric_limits<double>::infinity()),
                    Catch::Matchers::StartsWith("sigma_tau2"));  // inf itself: the finite check names it
  CHECK_THROWS_WITH(
      ConstantVelocityClock2(10.0, 1e308, 1.0),
      Catch::Matchers::StartsWith("dt, sigma_v2, sigma_tau2: the transition F or process noise Q"));
  CHECK_THROWS_WITH(TwoWayClock(1.0, 1e200, 1.0, 1.0),
                    Catch::Matchers::StartsWith("dt, sigma_omega, sigma_phi, sigma_v: the transition F or"));
  CHECK(ConstantVelocity2(0.1, 1e10).Q().allFinite());  // large but representable: accepted
}

TEST_CASE("the additive-noise filters need finite noise moments, the augmented form does not",
          "[models][measurement][errors]") {
  MatX a(3, 2);
  a << 0, 0, 100, 0, 0, 100;
  MeasurementStack st(ConstantVelocity2::layout(), a, 2);
  const std::vector<noise::Distribution> heavy = {noise::Normal(0, 1),
                                                  noise::Gev(0.6, 1, 1)};  // variance inf
  st.add_toa(0, two(1, 1)).add_toa(1, heavy).add_toa(2, two(1, 1));
  CHECK_THROWS_WITH(st.check_finite_moments("Ukf"),
                    Catch::Matchers::StartsWith("measurements: row 1, condition 1: the noise Gev has mean") &&
                        Catch::Matchers::Contains("; Ukf uses the noise moments, which must be finite"));
  MeasurementStack ok(ConstantVelocity2::layout(), a, 2);
  ok.add_toa(0, two(1, 1)).add_toa(1, two(1, 1)).add_toa(2, two(1, 1));
  CHECK_NOTHROW(ok.check_finite_moments("Ukf"));
}

TEST_CASE("measurement stack rejects a layout whose indices leave the state",
          "[models][measurement][errors]") {
  MatX a(2, 2);
  a << 0, 0, 1, 1;
  // Every index field is checked: the rows read and write the state at them unchecked.
  StateLayout L = ConstantVelocity2::layout();  // dim 4
  L.clock_bias = 7;
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2),
                    "layout: clock_bias = 7 does not fit a state of 4 (-1 when absent) (take the layout from "
                    "the motion model)");
  L = ConstantVelocity2::layout();
  L.velocity = 3;  // a 2-D velocity block at 3 would end at 5
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2), Catch::Contains("layout: velocity = 3 does not fit"));
  L = ConstantVelocity2::layout();
  L.skew = -2;
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2), Catch::Contains("layout: skew = -2"));
  L = ConstantVelocity2::layout();
  L.offset = 4;
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2), Catch::Contains("layout: offset = 4"));
  L = ConstantVelocity2::layout();
  L.clock_drift = 10;
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2), Catch::Contains("layout: clock_drift = 10"));
  L = ConstantVelocity2::layout();
  L.position = 3;
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2),
                    "layout: position = 3 does not fit a state of 4 (take the layout from the motion model)");
  L = ConstantVelocity2::layout();
  L.space_dim = 4;
  CHECK_THROWS_WITH(MeasurementStack(L, a, 2), Catch::Contains("space_dim 2 or 3, got dim 4, space_dim 4"));
  // The layouts of every motion model pass.
  CHECK_NOTHROW(MeasurementStack(ConstantVelocityClock3::layout(), MatX::Zero(1, 3), 2));
  CHECK_NOTHROW(MeasurementStack(TwoWayClock::layout(), MatX::Zero(1, 2), 2));
}

TEST_CASE("measurement stack gives back what its rows hold: both TDOA noises, TWR parameters, linear h",
          "[models][measurement]") {
  MatX anchors(3, 2);
  anchors << 0, 0, 6, 0, 0, 8;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 2);
  const Vec<4> h(0.0, 1.0, 0.5, 0.0);
  st.add_toa(0, two(1, 2)).add_tdoa(1, 2, two(1, 2), two(3, 4)).add_linear(h, -1, two(5, 6));
  CHECK(st.noise(1, 1).variance() == 2.0 * 2.0);    // n_a
  CHECK(st.noise_b(1, 0).variance() == 3.0 * 3.0);  // n_b
  CHECK(st.noise_b(1, 1).variance() == 4.0 * 4.0);
  CHECK(st.linear_h(2) == VecX(h));
  CHECK_THROWS_WITH(st.noise_b(0, 0), "i: row 0 is not a TDOA row (only TDOA rows have a second noise)");
  CHECK_THROWS_WITH(st.linear_h(1), "i: row 1 is not a linear row");
  CHECK_THROWS_WITH(st.twr_params(0), "i: row 0 is not a two-way-ranging row");
  CHECK_THROWS_AS(st.noise_b(1, 2), std::out_of_range);
  CHECK_THROWS_AS(st.linear_h(3), std::out_of_range);

  MeasurementStack tw(TwoWayClock::layout(), anchors, 2);
  tw.add_twr(2, 1, 5e-6, 1e-6, 0.2e-9, {std::nullopt, nn::Normal(8.5e-9, 2e-9)});
  for (int i : {0, 1}) {  // either row of the pair
    const MeasurementStack::TwrParams& w = tw.twr_params(i);
    CHECK(w.delta_slot == 5e-6);
    CHECK(w.reply_delay == 1e-6);
    CHECK(w.sigma_m == 0.2e-9);
    REQUIRE(w.gamma.size() == 2);
    CHECK(!w.gamma[0].has_value());
    CHECK(w.gamma[1]->mean() == 8.5e-9);
  }
  // its noise is the TWR parameters': noise(i, z) says so instead of reading an empty table
  CHECK_THROWS_WITH(tw.noise(0, 1), "noise: row 0 is a two-way-ranging row; its noise is in twr_params(i)");
}
