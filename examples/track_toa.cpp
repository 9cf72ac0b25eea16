// README example: a UKF tracking a constant-velocity mobile from three TOA anchors, one of them NLOS.
#include <cstdio>

#include "nlosloc/nlosloc.hpp"

int main() {
  using namespace nlosloc;
  namespace nn = nlosloc::noise;
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);  // Ke and Wu eq. (16)
  MatX anchors(3, 2);
  anchors << 0, 0, 8600, 0, 4300, 7500;
  MeasurementStack meas(ConstantVelocity2::layout(), anchors, /*num_conditions=*/2);
  for (int b = 0; b < 3; ++b) meas.add_toa(b, {nn::Normal(0, 50), nn::ShiftedNormal(513, 436)});  // LOS, NLOS

  Gaussian<4> prior;
  prior.mean << 1000, 1000, 10, 15;
  prior.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  Ukf<ConstantVelocity2> ukf(motion, meas, prior, SigmaScheme::scaled(0.5, 2.0, 0.0));

  Rng rng(1);
  Vec<4> x = prior.mean;
  VecXi sight(3);
  sight << 0, 0, 1;  // anchor 2 is NLOS
  VecX y(3);
  for (int k = 0; k < 100; ++k) {
    x = motion.F() * x;
    meas.predict(x, 0.0, y);
    for (int i = 0; i < 3; ++i) y[i] += 50 * rng.normal();
    y[2] += 513 + 436 * rng.normal();
    if (k % 10 == 3) y[0] = NAN;  // a missing measurement is skipped for that step
    const StepResult r = ukf.step(y, sight);
    if (k % 20 == 19)
      std::printf("t = %4.1f s  error = %6.1f m  log p(y) = %7.2f  rows = %d\n", ukf.time(),
                  (ukf.mean().head<2>() - x.head<2>()).norm(), r.log_likelihood, r.rows_used);
  }
  return 0;
}
