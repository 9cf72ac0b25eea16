#pragma once
/// \file bind.hpp
/// The binding functions of nlosloc._core, one per submodule, each defined (at global scope) in
/// python/src/bind_<name>.cpp and called by module.cpp with the submodule it fills. A binding file keeps
/// its helpers and using-directives in a namespace of its own (nlosloc::bind_<name>_cpp): the module
/// compiles in unity batches (NLOSLOC_UNITY_PYTHON), where file-scope names would meet the next file's.
#include <pybind11/pybind11.h>

#include <memory>
#include <string>

namespace nlosloc::sim {
class Registry;
class Scenario;
}  // namespace nlosloc::sim

/// nlosloc.core: aliases, Gaussian, sigma points, robust Cholesky, log-sum-exp, Rng (bind_core.cpp).
void bind_core(pybind11::module_& m);
/// nlosloc.noise: noise distributions, pdf, sampling, Gaussian-quantile transform (bind_noise.cpp).
void bind_noise(pybind11::module_& m);
/// nlosloc.models: motion and measurement models (bind_models.cpp).
void bind_models(pybind11::module_& m);
/// nlosloc.situation: sight Markov models, quality likelihoods, forward filter (bind_situation.cpp).
void bind_situation(pybind11::module_& m);
/// nlosloc.rbpf: RBPF (classical, reordered), merge/prune, joint PF (bind_rbpf.cpp).
void bind_rbpf(pybind11::module_& m);
/// nlosloc.snapshot: MLE-LOS, CHEN, CONG, URR baselines (bind_snapshot.cpp).
void bind_snapshot(pybind11::module_& m);
/// nlosloc.mitigation: Ke and Wu QP-bias EKF, iterated NLOS EKF, QP adapter (bind_mitigation.cpp).
void bind_mitigation(pybind11::module_& m);
/// nlosloc.bounds: GCRB (bind_bounds.cpp).
void bind_bounds(pybind11::module_& m);
/// nlosloc.filters: KF, EKF, UKF (bind_filters.cpp); the IUKF, RBPF and PF are in nlosloc.rbpf.
void bind_filters(pybind11::module_& m);
/// nlosloc.sim: trajectories, scenarios, Monte Carlo runner, metrics (bind_sim.cpp), which calls the three
/// below after it has registered Scenario.
void bind_sim(pybind11::module_& m);
/// nlosloc.sim, part 2: K1, K2, K3 and their parameters, the K2 study (bind_sim_ke_wu.cpp).
void bind_sim_ke_wu(pybind11::module_& m);
/// nlosloc.sim, part 3: summaries, text tables, estimator_seed, percentile (bind_sim_report.cpp).
void bind_sim_report(pybind11::module_& m);
/// nlosloc.sim, part 4: CustomScenario, a scenario defined in Python (bind_sim_custom.cpp).
void bind_sim_custom(pybind11::module_& m);
/// The built-in registry (nlosloc::sim::registry()), defined in bind_sim.cpp: the only file that includes
/// its inline definition, since every file that does compiles every scenario's estimators (about 140 s).
const nlosloc::sim::Registry& python_registry();
/// Python's repr of a float ("2.0", "1e-07", "inf"): the shortest text that reads back as v, for the
/// classes' __repr__ (std::to_string prints six decimals: 1e-7 as "0.000000").
inline std::string float_repr(double v) { return pybind11::repr(pybind11::float_(v)).cast<std::string>(); }
/// The scenario registered as `name` (ValueError listing the names otherwise), as the non-const pointer
/// pybind11's Scenario holder takes: scenarios have no mutators, so sharing the registered object is safe.
std::shared_ptr<nlosloc::sim::Scenario> registered_scenario(const std::string& name);
