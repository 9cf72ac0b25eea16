#pragma once
/// \file bind.hpp
/// The binding functions of nlosloc._core, one per submodule, each defined (at global scope) in
/// python/src/bind_<name>.cpp and called by module.cpp with the submodule it fills.
#include <pybind11/pybind11.h>

/// nlosloc.core: aliases, Gaussian, sigma points, robust Cholesky, log-sum-exp, Rng (bind_core.cpp).
void bind_core(pybind11::module_& m);
/// nlosloc.noise: noise distributions, pdf, sampling, Gaussian-quantile transform (bind_noise.cpp).
void bind_noise(pybind11::module_& m);
/// nlosloc.models: motion and measurement models (bind_models.cpp).
void bind_models(pybind11::module_& m);
/// nlosloc.filters: KF, EKF, UKF, IUKF, RBPF and the other estimators (bind_filters.cpp).
void bind_filters(pybind11::module_& m);
/// nlosloc.sim: trajectories, scenarios, Monte Carlo runner, metrics (bind_sim.cpp).
void bind_sim(pybind11::module_& m);
