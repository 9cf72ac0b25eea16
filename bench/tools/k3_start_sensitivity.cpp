// K3 P(error <= 5 m) of the proposed tracker for several start positions (Ke and Wu do not give theirs;
// scenarios.md takes (20, 20)). The bad geometry's nodes lie near the line y = x, and (20, 20) is on it, so
// the cross-line coordinate is observed only through the range curvature; this shows how much the bad
// geometry's figures depend on that choice. Not part of the build:
//   g++ -std=c++17 -O2 -DNLOSLOC_HAVE_PROXSUITE -I include -I /usr/include/eigen3
//       -I .venv/lib/python3.11/site-packages/cmeel.prefix/include bench/tools/k3_start_sensitivity.cpp
//       -pthread -o /tmp/k3_start && /tmp/k3_start
#include <cstdio>

#include "nlosloc/sim/k3.hpp"

int main() {
  using namespace nlosloc;
  for (const Vec<2>& start :
       {Vec<2>(20, 20), Vec<2>(20, 40), Vec<2>(40, 20), Vec<2>(50, 20), Vec<2>(30, 60)}) {
    sim::K3Params p;
    p.start = start;
    const sim::K3 s(p);
    std::printf("start (%g, %g):", start[0], start[1]);
    for (const std::string& c : s.cases()) {
      sim::MonteCarloOptions o;
      o.runs = 100;
      o.seed = 1;
      const sim::EstimatorSpec est{"proposed", [](const sim::Scenario& sc, int ci) {
                                     return sim::make_k3_proposed(static_cast<const sim::K3&>(sc), ci);
                                   }};
      const sim::MonteCarloResult r = sim::run_monte_carlo(s, c, {est}, o);
      std::printf("  %s %.3f", c.c_str(),
                  sim::probability_within(sim::pooled_errors(r.estimators[0].errors, r.discard), 5.0));
    }
    std::printf("\n");
  }
  return 0;
}
