#pragma once
/// \file registry.hpp
/// The built-in registry of scenarios and estimators used by nlosloc-bench and the Python bindings (its
/// contents: builtin.hpp).
///
/// Included on its own (users, the Python module), this header defines registry() inline. The C++ tests
/// and the bench link the build-tree object library nlosloc_registry instead, which defines
/// NLOSLOC_COMPILED_REGISTRY and compiles registry() once (src/registry.cpp): the estimators of every
/// scenario are most of the compile time of a file that calls registry(), and three of nlosloc's own do.
#include "nlosloc/sim/scenario.hpp"
#ifndef NLOSLOC_COMPILED_REGISTRY
#include "nlosloc/sim/builtin.hpp"
#endif

namespace nlosloc::sim {

/// The registry with every built-in scenario and estimator; built on first use (thread-safe), then read-only.
#ifdef NLOSLOC_COMPILED_REGISTRY
const Registry& registry();  // src/registry.cpp
#else
inline const Registry& registry() {
  static const Registry r = nlosloc::detail::make_builtin_registry();
  return r;
}
#endif

}  // namespace nlosloc::sim
