// Micro-benchmarks of one filter step (predict + update). One templated body, one registration per
// filter/model pair. Median over repetitions is the figure reported for issue #2 (target: UKF 4-state,
// 3 TOA rows, <= 0.4 us per step).
#include <benchmark/benchmark.h>

#include "nlosloc/core/random.hpp"
#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"

namespace {
using namespace nlosloc;
namespace nn = nlosloc::noise;

/// K1 geometry: 3 TOA anchors, CV model with white acceleration (Ke and Wu eq. 16).
MeasurementStack toa3(int conditions) {
  MatX anchors(3, 2);
  anchors << 0, 0, 8600, 0, 4300, 7500;
  MeasurementStack st(ConstantVelocity2::layout(), anchors, conditions);
  for (int b = 0; b < 3; ++b) {
    std::vector<noise::Distribution> n{nn::Normal(0, 50)};
    if (conditions == 2) n.push_back(nn::Rayleigh::from_variance(2000.0));
    st.add_toa(b, n);
  }
  return st;
}

/// Pre-drawn track of 1024 measurement vectors, cycled through by the benchmark loop.
struct Track {
  std::vector<VecX> y;
  Gaussian<4> init;
  explicit Track(const MeasurementStack& st) {
    const ConstantVelocity2 motion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);
    Rng rng(1);
    Vec<4> x(1000, 1000, 10, 15);
    init.mean = x;
    init.cov = Vec<4>(2500, 2500, 100, 100).asDiagonal();
    for (int k = 0; k < 1024; ++k) {
      x = motion.F() * x;
      VecX z(st.rows());
      st.predict(x, 0.0, z);
      for (int i = 0; i < z.size(); ++i) z[i] += 50 * rng.normal();
      y.push_back(z);
    }
  }
};

template <class Filter, class Make>
void run_steps(benchmark::State& state, Make make, int conditions) {
  const MeasurementStack st = toa3(conditions);
  const Track tr(st);
  Filter f = make(st, tr.init);
  std::size_t k = 0;
  for (auto _ : state) {
    const StepResult r = f.step(tr.y[k & 1023]);
    benchmark::DoNotOptimize(r.log_likelihood);
    if ((++k & 1023) == 0) f.set_belief(tr.init);  // keep the track and filter in step
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

const ConstantVelocity2 kMotion(0.1, 1.0, VelocityNoise::kWhiteAcceleration);

void BM_Ukf_CV2_Toa3(benchmark::State& s) {
  run_steps<Ukf<ConstantVelocity2>>(
      s,
      [](const MeasurementStack& st, const Gaussian<4>& g) {
        return Ukf<ConstantVelocity2>(kMotion, st, g, SigmaScheme::scaled(0.5, 2.0, 0.0));
      },
      1);
}
void BM_UkfAugmented_CV2_Toa3_Rayleigh(benchmark::State& s) {
  run_steps<UkfAugmented<ConstantVelocity2>>(
      s,
      [](const MeasurementStack& st, const Gaussian<4>& g) {
        return UkfAugmented<ConstantVelocity2>(kMotion, st, g, SigmaScheme::scaled(0.5, 2.0, 0.0));
      },
      2);
}
void BM_Ekf_CV2_Toa3(benchmark::State& s) {
  run_steps<Ekf<ConstantVelocity2>>(
      s,
      [](const MeasurementStack& st, const Gaussian<4>& g) { return Ekf<ConstantVelocity2>(kMotion, st, g); },
      1);
}
void BM_Kf_CV2_Pos3(benchmark::State& s) {
  // Linear rows of the same size as the TOA stack, for the KF floor.
  MatX H = MatX::Zero(3, 4);
  H(0, 0) = 1;
  H(1, 1) = 1;
  H(2, 0) = H(2, 1) = 1;
  const MatX R = 2500.0 * MatX::Identity(3, 3);
  const MeasurementStack st = toa3(1);
  const Track tr(st);
  Kf<ConstantVelocity2> f(kMotion, H, R, tr.init);
  std::size_t k = 0;
  for (auto _ : s) {
    const StepResult r = f.step(tr.y[k & 1023]);
    benchmark::DoNotOptimize(r.log_likelihood);
    if ((++k & 1023) == 0) f.set_belief(tr.init);
  }
  s.SetItemsProcessed(static_cast<int64_t>(s.iterations()));
}
}  // namespace

BENCHMARK(BM_Ukf_CV2_Toa3);
BENCHMARK(BM_UkfAugmented_CV2_Toa3_Rayleigh);
BENCHMARK(BM_Ekf_CV2_Toa3);
BENCHMARK(BM_Kf_CV2_Pos3);
BENCHMARK_MAIN();
