#pragma once
// The H2-like model of the RBPF micro-benchmarks (bench/micro_rbpf.cpp) and of the phase timeline
// (bench/phases/rbpf_phases.cpp): Huerta Sec. VI-B, 6 anchors on a hexagon of 3 km, RTOA, 6-state
// [p, tau, v, tau_dot], LOS Normal var 10 / NLOS Rayleigh var 5000, speed-dependent sight chain with
// E{L} = 10 m, Beta quality statistics, and a pre-drawn 1024-step track the loops cycle through.
#include <cmath>
#include <vector>

#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/core/types.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"
#include "nlosloc/models/noise.hpp"
#include "nlosloc/situation/markov.hpp"
#include "nlosloc/situation/quality.hpp"

namespace nlosloc::bench {

/// H2-like model and track (see the file comment).
struct H2Model {
  ConstantVelocityClock2 motion{0.01, 1.0, 1e-2};
  MeasurementStack st{ConstantVelocityClock2::layout(), anchors(), 2};
  situation::SightProcess proc{situation::SightModel::speed_dependent(10, 10, 0.01), 6};
  situation::QualityModel q{{noise::Beta(4, 1.5), noise::Beta(1.5, 4)}};
  Gaussian<6> init;
  std::vector<VecX> y, o;

  H2Model() {
    for (int b = 0; b < 6; ++b)
      st.add_rtoa(b, {noise::Normal(0, std::sqrt(10.0)), noise::Rayleigh::from_variance(5000)});
    init.mean.setZero();
    init.cov = Vec<6>(25, 25, 10, 1, 1, 10).asDiagonal();
    // a pre-drawn 1024-step track (random-walk mobile, sight from the chain), cycled by the loops
    Rng rng(1);
    Vec<6> x = Vec<6>::Zero();
    VecXi s = proc.sample_initial(rng);
    for (int k = 1; k <= 1024; ++k) {
      x = motion.F() * x;
      x(3) += 0.1 * rng.normal();
      x(4) += 0.1 * rng.normal();
      x(5) += 0.01 * rng.normal();
      VecX w(6);
      situation::transversal_speeds(x.head<2>(), x.segment<2>(3), st.anchors(), w);
      s = proc.sample_next(s, k, w, rng);
      VecX yk(6);
      st.predict(x, 0.0, yk);
      for (int b = 0; b < 6; ++b) yk(b) += st.noise(b, s(b)).sample(rng);
      y.push_back(yk);
      o.push_back(q.sample(s, rng));
    }
  }
  static MatX anchors() {
    MatX a(6, 2);
    for (int b = 0; b < 6; ++b) {
      a(b, 0) = 3000 * std::cos(b * kPi / 3);
      a(b, 1) = 3000 * std::sin(b * kPi / 3);
    }
    return a;
  }
};

/// The model, built once.
inline const H2Model& model() {
  static const H2Model m;
  return m;
}

}  // namespace nlosloc::bench
