#pragma once
/// \file builtin.hpp
/// The built-in scenarios and their estimators, as one registration function. Adding a scenario is one
/// register_<name>(r) line here; adding an estimator to a scenario is one r.add_estimator<Scenario>(...)
/// line in that scenario's register function. registry() (registry.hpp) holds the registry it fills.
#include "nlosloc/sim/h1.hpp"
#include "nlosloc/sim/h2.hpp"
#include "nlosloc/sim/k1.hpp"
#include "nlosloc/sim/k2.hpp"
#include "nlosloc/sim/k3.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::detail {

/// A registry with every built-in scenario and estimator: what registry() holds (the API is registry(),
/// the same in C++ and Python; this is how its two definitions fill it).
inline sim::Registry make_builtin_registry() {
  sim::Registry reg;
  sim::register_k1(reg);  // Ke & Wu 2011 Sec. 6.1
  sim::register_k2(reg);  // Ke & Wu 2011 Sec. 6.2
  sim::register_k3(reg);  // Ke & Wu 2011 Sec. 6.4
  sim::register_h1(reg);  // Huerta et al. 2009 Sec. VI-A
  sim::register_h2(reg);  // Huerta et al. 2009 Sec. VI-B
  return reg;
}

}  // namespace nlosloc::detail
