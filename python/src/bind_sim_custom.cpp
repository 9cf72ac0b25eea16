/// \file bind_sim_custom.cpp
/// Tools for scenarios and estimators written in Python: backdate (the registered RBPF and PF's start rule)
/// and nlosloc.sim.CustomScenario, a scenario defined in Python (its measurement stack, cases, length, period
/// and a generate(case_index, steps, rng) callable returning the draw's arrays), so Python users run the
/// Monte Carlo runner, the metrics and the tables on their own simulations or recordings, as C++ users
/// do with their own sim::Scenario. It runs with Python estimators and filters of nlosloc.filters (no
/// estimator is registered for it). generate() is called from the runner's workers with the GIL taken.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "bind.hpp"
#include "field_value.hpp"
#include "motion_arg.hpp"
#include "nlosloc/core/cholesky.hpp"
#include "nlosloc/sim/h1.hpp"
#include "nlosloc/sim/scenario.hpp"
#include "py_estimator.hpp"

namespace py = pybind11;
namespace sim = nlosloc::sim;
using nlosloc::MatX;
using nlosloc::MeasurementStack;
using nlosloc::Rng;
using nlosloc::VecX;

namespace {

/// Settings of a CustomScenario, checked at construction.
struct CustomSpec {
  std::string name, description;
  std::vector<std::string> cases, choices;
  int steps = 0, discard = 0;
  double dt = 0.0;
};

class CustomScenario final : public sim::Scenario {
 public:
  /// With the GIL held.
  CustomScenario(CustomSpec spec, const MeasurementStack& meas, const py::object& generate)
      : spec_(std::move(spec)), meas_(meas), generate_(nlosloc::bind::share(generate)) {}

  std::string name() const override { return spec_.name; }
  std::string description() const override { return spec_.description; }
  std::vector<std::string> choices() const override { return spec_.choices; }
  std::vector<std::string> cases() const override { return spec_.cases; }
  int steps() const override { return spec_.steps; }
  double dt() const override { return spec_.dt; }
  MatX anchors() const override { return meas_.anchors(); }
  int discard() const override { return spec_.discard; }
  int state_dim() const override { return meas_.layout().dim; }
  const MeasurementStack& measurements() const override { return meas_; }
  const py::object& generator() const { return *generate_; }

 protected:
  /// Calls generate(c, T, rng) and checks every array of the dict it returns, naming the key.
  void generate(int c, int T, Rng& rng, sim::Draw& d) const override {
    py::gil_scoped_acquire gil;
    const py::object r = (*generate_)(c, T, py::cast(rng, py::return_value_policy::copy));
    if (!py::isinstance<py::dict>(r))
      throw py::type_error("generate: expected a dict of arrays, got an object of type " +
                           py::str(py::type::handle_of(r).attr("__name__")).cast<std::string>());
    const auto dict = py::reinterpret_borrow<py::dict>(r);
    const int n = state_dim(), D = space_dim(), m = meas_.rows(), B = meas_.num_anchors();
    auto matrix = [&](const char* key, int cols, bool required) -> sim::RowMatX {
      const std::string where = std::string("generate: '") + key + "'";
      if (!dict.contains(key)) {
        if (required) throw py::value_error(where + ": missing");
        return sim::RowMatX::Constant(T, cols, std::nan(""));
      }
      const auto a = nlosloc::bind::real_array(dict[key], where.c_str());
      if (!a || a.ndim() != 2 || a.shape(0) != T || a.shape(1) != cols)
        throw py::value_error(where + ": expected an array of shape (" + std::to_string(T) + ", " +
                              std::to_string(cols) + ")");
      return Eigen::Map<const sim::RowMatX>(a.data(), T, cols);
    };
    d.states = matrix("states", n, true);
    d.positions = matrix("positions", D, true);
    d.y = matrix("y", m, true);
    d.quality = matrix("quality", B, false);
    if (!d.states.allFinite() || !d.positions.allFinite())
      throw py::value_error("generate: 'states' and 'positions': expected finite values");
    // NaN = missing; inf is an error, as for every filter (the quality statistics too: they were let through)
    const auto finite_or_missing = [](const char* key, const sim::RowMatX& v) {
      for (Eigen::Index k = 0; k < v.rows(); ++k)
        for (Eigen::Index i = 0; i < v.cols(); ++i)
          if (std::isinf(v(k, i)))
            throw py::value_error(std::string("generate: '") + key +
                                  "': expected finite values or NaN (missing), got inf at (" +
                                  std::to_string(k) + ", " + std::to_string(i) + ")");
    };
    finite_or_missing("y", d.y);
    finite_or_missing("quality", d.quality);
    if (!dict.contains("sight")) throw py::value_error("generate: 'sight': missing");
    int ndim = 0;
    const auto sight = nlosloc::bind::to_int_rows(dict["sight"], "generate: 'sight'", &ndim);
    if (ndim != 2 || sight.rows() != T || sight.cols() != B)
      throw py::value_error("generate: 'sight': expected an integer array of shape (" + std::to_string(T) +
                            ", " + std::to_string(B) + ")");
    for (Eigen::Index k = 0; k < T; ++k)
      for (Eigen::Index b = 0; b < B; ++b)
        if (sight(k, b) < 0 || sight(k, b) >= meas_.num_conditions())
          throw py::value_error("generate: 'sight': expected conditions in [0, " +
                                std::to_string(meas_.num_conditions()) + "), got " +
                                std::to_string(sight(k, b)) + " at (" + std::to_string(k) + ", " +
                                std::to_string(b) + ")");
    d.sight = sight;
    for (const char* key : {"initial_mean", "initial_cov"})
      if (!dict.contains(key)) throw py::value_error(std::string("generate: '") + key + "': missing");
    d.initial_mean = nlosloc::bind::to_vector(dict["initial_mean"], "generate: 'initial_mean'");
    d.initial_cov = nlosloc::bind::to_matrix(dict["initial_cov"], "generate: 'initial_cov'");
    nlosloc::detail::ensure_shape(d.initial_mean, n, 1, "generate: 'initial_mean'");
    nlosloc::detail::ensure_shape(d.initial_cov, n, n, "generate: 'initial_cov'");
    if (!d.initial_mean.allFinite() || !nlosloc::is_spd(d.initial_cov))
      throw py::value_error(
          "generate: 'initial_mean', 'initial_cov': expected a finite mean and a symmetric positive definite "
          "covariance");
  }

 private:
  CustomSpec spec_;
  MeasurementStack meas_;
  nlosloc::bind::SharedObject generate_;  // the last owner may be a runner's worker
};

std::shared_ptr<CustomScenario> make_custom(const std::string& name, const MeasurementStack& meas,
                                            const std::vector<std::string>& cases, int steps, double dt,
                                            const py::object& generate, int discard,
                                            const std::string& description,
                                            const std::vector<std::string>& choices) {
  if (name.empty()) throw py::value_error("name: expected a non-empty name");
  if (python_registry().has_scenario(name))
    throw py::value_error("name: '" + name + "' is a built-in scenario; choose another name");
  if (cases.empty()) throw py::value_error("cases: expected at least one case name");
  if (std::set<std::string>(cases.begin(), cases.end()).size() != cases.size())
    throw py::value_error("cases: expected distinct case names");
  if (!(steps >= 1)) throw py::value_error("steps: expected >= 1, got " + std::to_string(steps));
  if (!(discard >= 0 && discard < steps))
    throw py::value_error("discard: expected 0 <= discard < steps, got " + std::to_string(discard));
  if (!(dt > 0.0 && std::isfinite(dt))) throw py::value_error("dt: expected a finite period > 0");
  if (PyCallable_Check(generate.ptr()) == 0)
    throw py::type_error("generate: expected a callable generate(case_index, steps, rng) -> dict");
  if (meas.rows() == 0) throw py::value_error("measurements: expected a stack with at least one row");
  CustomSpec spec{name, description, cases, choices, steps, discard, dt};
  return std::make_shared<CustomScenario>(std::move(spec), meas, generate);
}

}  // namespace

void bind_sim_custom(py::module_& m) {
  m.def(
      "backdate",
      [](const py::object& motion, const nlosloc::bind::VecArg& mean_in,
         const nlosloc::bind::MatArg& cov_in) {
        const VecX mean = mean_in.get("mean");
        const MatX cov = cov_in.get("cov");
        return std::visit(
            [&](const auto& mo) {
              using Mo = std::decay_t<decltype(mo)>;
              const auto g = sim::backdate(mo, nlosloc::bind::to_belief<Mo::kDim>(mean, cov, "mean", "cov"));
              return py::make_tuple(VecX(g.mean), MatX(g.cov));
            },
            nlosloc::bind::to_motion(motion));
      },
      py::arg("motion"), py::arg("mean"), py::arg("cov"),
      "The belief (mean, cov) one prediction earlier whose prediction is the given one exactly: F^-1 m, "
      "F^-1 (P - Q) F^-T; the given belief itself when P - Q is not positive definite. A filter that "
      "predicts before its first update, started from it, sees the draw's initial belief at t_0.");

  py::class_<CustomScenario, sim::Scenario, std::shared_ptr<CustomScenario>>(
      m, "CustomScenario",
      R"doc(A scenario defined in Python: your own simulation, or a recording replayed.

It runs wherever a Scenario does (``draw``, ``run_monte_carlo(scenario, ...)``,
``nlosloc.montecarlo.run``, ``summarize`` and the tables) with estimators written in Python and
filters of :mod:`nlosloc.filters` (no estimator is registered for it). ``generate`` is called from
the runner's worker threads, with the GIL; it must not depend on anything but its arguments if the
result is to be the same for any number of threads. Scenario objects of this class do not pickle.)doc")
      .def(py::init(nlosloc::bind::strict_fn(&make_custom, "name", "measurements", "cases", "steps", "dt",
                                             "generate", "discard", "description", "choices")),
           py::arg("name"), py::arg("measurements"), py::arg("cases"), py::arg("steps"), py::arg("dt"),
           py::arg("generate"), py::arg("discard") = 0, py::arg("description") = "",
           py::arg("choices") = std::vector<std::string>{},
           R"doc(Parameters
----------
name : str
    Scenario name (not one of the built-in ones).
measurements : nlosloc.models.MeasurementStack
    The stack that generates ``y`` (its rows, anchors, conditions; its layout's state size is the
    true state's).
cases : list of str
    Case names; ``generate`` receives the index of one.
steps : int
    Default number of steps T of a run (>= 1).
dt : float
    Sampling period (s), > 0.
generate : callable
    ``generate(case_index, steps, rng)`` with ``rng`` a ``core.Rng(seed, run)`` (a copy): returns a
    dict of ``states`` (T, n), ``positions`` (T, D), ``y`` (T, m; NaN = missing), ``sight``
    (T, B) integers in [0, N_z), optionally ``quality`` (T, B; NaN when absent), and
    ``initial_mean`` (n,), ``initial_cov`` (n, n) (the belief every estimator starts from).
    Checked on every call (ValueError naming the key).
discard : int, default 0
    First samples of every run left out of the statistics (< steps).
description : str, optional
choices : list of str, optional
    Values you chose, printed with the tables.)doc")
      .def_property_readonly("generate", &CustomScenario::generator, "The generate callable.");
}
