// H2: 90% error points of IUKF and the three RBPFs as the quality statistic weakens. Tests the explanation
// of why rRBPF-16, rRBPF-128 and cRBPF-128 coincide in our H2 (scenarios.md's Beta(4, 1.5) / Beta(1.5, 4)
// statistic, drawn every step for every anchor, may leave little situation uncertainty for more particles
// to resolve). Not part of the build:
//   g++ -std=c++17 -O2 -DNDEBUG -I include -I /usr/include/eigen3 bench/tools/h2_quality_sensitivity.cpp \
//       -pthread -o /tmp/h2_quality && /tmp/h2_quality [runs] [steps]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "nlosloc/sim/h2.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"

int main(int argc, char** argv) {
  using namespace nlosloc;
  const int runs = argc > 1 ? std::atoi(argv[1]) : 20;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 2000;
  // (a, b) of Beta(a, b) for LOS; NLOS uses Beta(b, a). a = b: the statistic carries no information.
  const double forms[][2] = {{4.0, 1.5}, {2.0, 1.5}, {1.5, 1.5}};
  for (const auto& f : forms) {
    sim::H2Params p;
    p.steps = steps;
    p.quality_los_a = p.quality_nlos_b = f[0];
    p.quality_los_b = p.quality_nlos_a = f[1];
    const sim::H2 s(p);
    auto spec = [](const char* name, auto make) {
      return sim::EstimatorSpec{name, [make](const sim::Scenario& sc, int ci) {
                                  return make(static_cast<const sim::H2&>(sc), ci);
                                }};
    };
    const std::vector<sim::EstimatorSpec> est{
        spec(sim::H2::kIukf, sim::make_h2_iukf), spec(sim::H2::kCrbpf128, sim::make_h2_crbpf128),
        spec(sim::H2::kRrbpf16, sim::make_h2_rrbpf16), spec(sim::H2::kRrbpf128, sim::make_h2_rrbpf128)};
    sim::MonteCarloOptions o;
    o.runs = runs;
    o.seed = 1;
    const sim::MonteCarloResult r = sim::run_monte_carlo(s, "default", est, o);
    std::printf("quality LOS Beta(%g, %g), NLOS Beta(%g, %g), %d runs x %d steps, 90%% error (m):", f[0],
                f[1], f[1], f[0], runs, steps);
    for (const auto& e : r.estimators)
      std::printf("  %s %.3f", e.name.c_str(),
                  sim::percentiles(sim::pooled_errors(e.errors, r.discard), {90.0})[0]);
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}
