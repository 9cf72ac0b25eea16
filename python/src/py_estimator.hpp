#pragma once
/// \file py_estimator.hpp
/// Estimators written in Python for the Monte Carlo runner (nlosloc.sim.run_monte_carlo), beside the
/// registered C++ ones: C++ users pass their own sim::Estimator in an EstimatorSpec, and this gives Python
/// users the same. Defined in py_estimator.cpp; also the draw dict that nlosloc.sim.draw() returns.
#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <vector>

#include "nlosloc/sim/montecarlo.hpp"
#include "nlosloc/sim/scenario.hpp"
#include "py_object.hpp"

namespace nlosloc::bind {

/// The dict of one draw: states, positions, y, sight, quality, initial_mean, initial_cov (numpy arrays)
/// and scenario, case, seed, run, dt. Takes the draw by value: a temporary's arrays move into numpy.
pybind11::dict draw_to_dict(sim::Draw d);

/// The runner's estimators from the `estimators` argument of run_monte_carlo, for `scenario` (given to the
/// factories as its Python object):
///  - None or empty: every estimator registered in `reg` under the scenario's name;
///  - otherwise each entry is a registered name (str) or a pair (name, factory), where
///    factory(scenario, case_index) returns an object with reset(draw, rng) and step(k, y, o) -> the (D,)
///    position estimate, and optionally sight_estimate() -> (B,) integer conditions.
///  - or a tuple (name, filter) with an object that runs natively (no GIL) through the C++ adapter of its
///    kind: an Ekf, Ukf or UkfAugmented of nlosloc.filters (a copy per worker; (name, filter, sight) with
///    sight "assume_los", the default, or "oracle"), an Iukf, Rbpf or ParticleFilter of nlosloc.rbpf (a new
///    filter with its models and options), a QpBiasEkf or BiasAugmentedEkf of nlosloc.mitigation, or a
///    snapshot baseline (MleLos, Chen, Cong, Urruela); a factory may return one of them too.
/// TypeError / ValueError naming `estimators` on a malformed entry. Call with the GIL held.
std::vector<sim::EstimatorSpec> estimator_specs(const sim::Registry& reg,
                                                const std::shared_ptr<sim::Scenario>& scenario,
                                                const std::optional<pybind11::sequence>& estimators);

}  // namespace nlosloc::bind
