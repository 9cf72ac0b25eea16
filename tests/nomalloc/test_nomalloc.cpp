// No heap allocation in a filter step: built as its own executable with EIGEN_RUNTIME_NO_MALLOC, so any
// Eigen allocation inside step() aborts the test (Eigen's own check, not a timing or a guess).
#define EIGEN_RUNTIME_NO_MALLOC
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"

using namespace nlosloc;
namespace nn = nlosloc::noise;

namespace {
struct NoMalloc {
  NoMalloc() { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoMalloc() { Eigen::internal::set_is_malloc_allowed(true); }
};

MeasurementStack stack_with_angles() {
  MatX anchors(3, 2);
  anchors << 0, 0, 8600, 0, 4300, 7500;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, 2);
  for (int b = 0; b < 3; ++b) st.add_toa(b, {nn::Normal(0, 50), nn::Rayleigh::from_variance(2000.0)});
  st.add_aoa(0, {nn::Normal(0, 0.01), nn::Normal(0, 0.05)});
  st.add_tdoa(1, 2, {nn::Normal(0, 50), nn::Normal(0, 80)}, {nn::Normal(0, 50), nn::Normal(0, 80)});
  return st;
}

template <class F>
void run_without_malloc(F& f, int rows, int anchors) {
  VecX y(rows);
  y.setConstant(3000.0);
  y[3] = 0.7;         // the AOA row
  y[rows - 1] = NAN;  // a missing row
  VecXi s = VecXi::Zero(anchors);
  s[1] = 1;
  StepResult r;
  {
    NoMalloc guard;
    for (int k = 0; k < 5; ++k) r = f.step(y, s);
    f.predict();
  }
  CHECK(r.rows_used == rows - 1);
  CHECK(std::isfinite(r.log_likelihood));
}
}  // namespace

TEST_CASE("filter steps do not allocate", "[nomalloc]") {
  const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
  Gaussian<4> g;
  g.mean << 1000, 1000, 10, 15;
  g.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
  const MeasurementStack st = stack_with_angles();
  Ukf<ConstantVelocity2> ukf(motion, st, g);
  UkfAugmented<ConstantVelocity2> aug(motion, st, g);
  Ekf<ConstantVelocity2> ekf(motion, st, g);
  run_without_malloc(ukf, st.rows(), st.num_anchors());
  run_without_malloc(aug, st.rows(), st.num_anchors());
  run_without_malloc(ekf, st.rows(), st.num_anchors());
  MatX H = MatX::Zero(2, 4);
  H(0, 0) = H(1, 1) = 1;
  Kf<ConstantVelocity2> kf(motion, H, MatX::Identity(2, 2), g);
  VecX y(2);
  y << 1000, NAN;
  {
    NoMalloc guard;
    for (int k = 0; k < 5; ++k) kf.step(y);
  }
  CHECK(kf.mean().allFinite());
}
