#pragma once
/// \file native_makers.hpp
/// The native Monte Carlo estimators of objects built in Python: the (name, object) entries of
/// estimator_specs (py_estimator.hpp). One maker per family, each defined in the binding file that already
/// instantiates the family's templates (bind_rbpf.cpp, bind_mitigation.cpp, bind_snapshot.cpp): in
/// py_estimator.cpp they compiled the RBPF, PF and IUKF for every motion model a second time (170 s of the
/// wheel's build).
#include <pybind11/pybind11.h>

#include <functional>
#include <memory>
#include <string>

#include "nlosloc/core/types.hpp"
#include "nlosloc/sim/scenario.hpp"

namespace nlosloc::bind {

/// Makes one runner estimator over a copy of (or, for the particle filters, a filter built with the set-up
/// of) an object given from Python, as it was when given; the Python object is not touched, and the
/// estimators run without the GIL.
using NativeMaker = std::function<std::unique_ptr<sim::Estimator>()>;

/// "estimators: the <what> of '<name>' ", for the messages (py_estimator.cpp).
std::string who(const std::string& name, const char* what);

/// ValueError naming the estimator when an object's state size, measurement rows, anchors or time step
/// differ from scenario s's (dt NaN: not checked; anchors -1 likewise) (py_estimator.cpp).
void check_fit(const std::string& name, const char* what, int n, Eigen::Index rows, Eigen::Index anchors,
               double dt, const sim::Scenario& s);

/// rbpf.Iukf, Rbpf or ParticleFilter (bind_rbpf.cpp); null for anything else. With the GIL.
NativeMaker rbpf_maker(const pybind11::handle& h, const std::string& name, const sim::Scenario& s);
/// mitigation.QpBiasEkf or BiasAugmentedEkf (bind_mitigation.cpp); null otherwise. With the GIL.
NativeMaker mitigation_maker(const pybind11::handle& h, const std::string& name, const sim::Scenario& s);
/// snapshot.MleLos, Chen, Cong or Urruela (bind_snapshot.cpp); null otherwise. With the GIL.
NativeMaker snapshot_maker(const pybind11::handle& h, const std::string& name, const sim::Scenario& s);

}  // namespace nlosloc::bind
