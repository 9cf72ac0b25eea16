/// \file registry.cpp
/// registry() compiled once for nlosloc's own targets (object library nlosloc_registry, which defines
/// NLOSLOC_COMPILED_REGISTRY for this file and for the targets that link it; see registry.hpp).
#include "nlosloc/sim/registry.hpp"

#include "nlosloc/sim/builtin.hpp"

#ifndef NLOSLOC_COMPILED_REGISTRY
#error "src/registry.cpp belongs to the nlosloc_registry target, which defines NLOSLOC_COMPILED_REGISTRY"
#endif

namespace nlosloc::sim {

// Every member of the RBPF adapters of H1 and H2, also those the registry never calls, so the tests'
// build compiles them all (once, here).
template class RbpfEstimator<ConstantVelocity2>;
template class RbpfEstimator<ConstantVelocityClock2>;

const Registry& registry() {
  static const Registry r = nlosloc::detail::make_builtin_registry();
  return r;
}

}  // namespace nlosloc::sim
