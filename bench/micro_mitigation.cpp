/// \file micro_mitigation.cpp
/// Time per step of Ke & Wu 2011's three trackers on K1 draws (Table 2): the proposed QP-bias EKF, the
/// iterated NLOS (bias-augmented) EKF and the EKF, in the 3 LOS / 0 NLOS and 0 LOS / 3 NLOS cases (the
/// proposed one also with proxsuite's QP), plus the box-QP solve alone with each solver. One templated body,
/// registered per tracker with one line each.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/mitigation/mitigation.hpp"
#include "nlosloc/sim/k1.hpp"

namespace {
using namespace nlosloc;
using nlosloc::sim::K1;

const K1& k1() {
  static const K1 s;
  return s;
}

/// One K1 draw (2000 steps) per case index, generated once.
const sim::Draw& draw(int c) {
  static const sim::Draw d[4] = {k1().draw(k1().cases()[0], 1, 0), k1().draw(k1().cases()[1], 1, 0),
                                 k1().draw(k1().cases()[2], 1, 0), k1().draw(k1().cases()[3], 1, 0)};
  return d[c];
}

struct Proposed {
  static mitigation::QpBiasEkf make(const Gaussian<4>& g) {
    mitigation::QpBiasEkfOptions o;
    o.noise.sigma0 = k1().params().sigma_los;
    return mitigation::QpBiasEkf(k1().motion(), k1().params().anchors, g, o);
  }
};
/// The same with proxsuite's dense QP for eq. (14) (the default is EnumerationBoxQp; README).
struct ProposedProxsuite {
  static mitigation::QpBiasEkf make(const Gaussian<4>& g) {
    mitigation::QpBiasEkfOptions o;
    o.noise.sigma0 = k1().params().sigma_los;
    return mitigation::QpBiasEkf(k1().motion(), k1().params().anchors, g, o,
                                 mitigation::make_proxsuite_box_qp(3));
  }
};
struct Iterated {
  static mitigation::BiasAugmentedEkf make(const Gaussian<4>& g) {
    mitigation::BiasAugmentedEkfOptions o;
    o.noise.sigma0 = k1().params().sigma_los;
    o.bias_prior_std = k1().params().iterated_bias_prior_std;
    o.bias_walk_std = k1().params().iterated_bias_walk_std;
    o.iterations = k1().params().iterated_iterations;
    return mitigation::BiasAugmentedEkf(k1().motion(), k1().params().anchors, g, o);
  }
};
struct PlainEkf {
  static Ekf<ConstantVelocity2> make(const Gaussian<4>& g) {
    return Ekf<ConstantVelocity2>(k1().motion(), k1().measurements(), g);
  }
};

/// Steps a tracker through the draw of case `state.range(0)` (restarting at its end); one iteration = one
/// step (predict + update), as in Ke & Wu Table 2 (s per 2000 steps).
template <class Maker>
void BM_K1Step(benchmark::State& state) {
  const sim::Draw& d = draw(static_cast<int>(state.range(0)));
  const Gaussian<4> g(d.initial_mean, d.initial_cov);
  auto f = Maker::make(g);
  const MatX Yt = d.y.transpose();
  int k = 0;
  for (auto _ : state) {
    if (k == d.steps()) {
      f.set_belief(g, 0.0);
      k = 0;
    }
    benchmark::DoNotOptimize(f.step(Yt.col(k)));
    ++k;
  }
  state.SetLabel(k1().cases()[static_cast<std::size_t>(state.range(0))]);
}

BENCHMARK_TEMPLATE(BM_K1Step, Proposed)->Arg(0)->Arg(3);
BENCHMARK_TEMPLATE(BM_K1Step, ProposedProxsuite)->Arg(0)->Arg(3);
BENCHMARK_TEMPLATE(BM_K1Step, Iterated)->Arg(0)->Arg(3);
BENCHMARK_TEMPLATE(BM_K1Step, PlainEkf)->Arg(0)->Arg(3);

/// The box QP of eq. (14) alone (3 variables, rank-1 Hessian as in K1's snapshot form), one solve:
/// Arg(0) proxsuite (init + solve), Arg(1) EnumerationBoxQp.
void BM_BoxQp3(benchmark::State& state) {
  std::unique_ptr<mitigation::BoxQp> qp;
  if (state.range(0) == 0) {
    qp = mitigation::make_proxsuite_box_qp(3);
  } else {
    qp = std::make_unique<mitigation::EnumerationBoxQp>(3);
  }
  state.SetLabel(qp->name());
  const Vec<3> c(0.5, 0.6, 0.62);
  const MatX H = 2.0 * c * c.transpose();
  const VecX g = -2.0 * 3.0 * c;
  const VecX lo = VecX::Zero(3), hi = VecX::Constant(3, 20.0);
  for (auto _ : state) benchmark::DoNotOptimize(qp->solve(H, g, lo, hi));
}
BENCHMARK(BM_BoxQp3)->Arg(0)->Arg(1);

}  // namespace
