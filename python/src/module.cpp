/// \file module.cpp
/// The extension module nlosloc._core; each submodule is filled by its bind_<name>.cpp (see bind.hpp).
/// Submodules are created in dependency order (core, noise, models, filters, sim) so that the types a
/// later submodule uses in its signatures are already registered.
#include <pybind11/pybind11.h>

#include "bind.hpp"

#ifndef NLOSLOC_VERSION_STRING
#error "NLOSLOC_VERSION_STRING must be defined by the build (CMakeLists.txt)"
#endif

PYBIND11_MODULE(_core, m) {
  m.doc() = "nlosloc compiled core (private; use the nlosloc package and its submodules).";
  m.attr("__version__") = NLOSLOC_VERSION_STRING;

  auto core = m.def_submodule("core", "Core types: Gaussian beliefs, sigma points, robust Cholesky, Rng.");
  bind_core(core);
  auto noise = m.def_submodule("noise", "Noise distributions: pdf, sampling, Gaussian-quantile transform.");
  bind_noise(noise);
  auto models = m.def_submodule("models", "Motion and measurement models (TOA, RTOA, TDOA, AOA, TWR).");
  bind_models(models);
  auto situation =
      m.def_submodule("situation", "Sight (LOS/NLOS) Markov models, quality likelihoods, HMM filter.");
  bind_situation(situation);
  auto filters = m.def_submodule(
      "filters", "Estimators: KF, EKF, UKF (the IUKF and the particle filters: nlosloc.rbpf).");
  bind_filters(filters);
  auto rbpf = m.def_submodule("rbpf", "Rao-Blackwellized particle filters with merge/prune, joint PF.");
  bind_rbpf(rbpf);
  auto snapshot = m.def_submodule("snapshot", "Per-epoch solvers and baselines: MLE-LOS, CHEN, CONG, URR.");
  bind_snapshot(snapshot);
  auto mitigation = m.def_submodule("mitigation", "Ke and Wu QP-bias EKF, bias-augmented EKF, QP adapter.");
  bind_mitigation(mitigation);
  auto bounds = m.def_submodule("bounds", "Performance bounds: GCRB (Huerta appendix).");
  bind_bounds(bounds);
  auto sim = m.def_submodule("sim", "Scenarios, simulator, Monte Carlo runner and metrics.");
  bind_sim(sim);
}
