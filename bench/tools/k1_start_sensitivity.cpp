// K1 EKF error percentiles for several start positions (Ke and Wu do not give theirs; scenarios.md takes
// (1000, 1000)). Shows how much the NLOS cases depend on that choice. Not part of the build:
//   g++ -std=c++17 -O2 -I include -I /usr/include/eigen3 bench/tools/k1_start_sensitivity.cpp -pthread
//       -o /tmp/k1_start && /tmp/k1_start
#include <cstdio>

#include "nlosloc/sim/k1.hpp"
#include "nlosloc/sim/metrics.hpp"
#include "nlosloc/sim/montecarlo.hpp"

int main() {
  using namespace nlosloc;
  for (const Vec<2>& start : {Vec<2>(1000, 1000), Vec<2>(0, 0), Vec<2>(500, 500), Vec<2>(2000, 2000)}) {
    sim::K1Params p;
    p.start = start;
    const sim::K1 s(p);
    std::printf("start (%g, %g):", start[0], start[1]);
    for (const std::string& c : s.cases()) {
      sim::MonteCarloOptions o;
      o.runs = 100;
      o.seed = 1;
      const sim::EstimatorSpec ekf{"EKF", [](const sim::Scenario& sc, int ci) {
                                     return sim::make_k1_ekf(static_cast<const sim::K1&>(sc), ci);
                                   }};
      const sim::MonteCarloResult r = sim::run_monte_carlo(s, c, {ekf}, o);
      const std::vector<double> q =
          sim::percentiles(sim::pooled_errors(r.estimators[0].errors, r.discard), {67.0, 95.0});
      std::printf("  %s %.1f/%.1f", c.c_str(), q[0], q[1]);
    }
    std::printf("\n");
  }
  return 0;
}
