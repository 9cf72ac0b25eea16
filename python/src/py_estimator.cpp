/// \file py_estimator.cpp
/// Python estimators in the Monte Carlo runner (py_estimator.hpp). The runner calls estimators from its
/// worker threads with the GIL released: each call into Python takes the GIL for its duration, so Python
/// estimators run one at a time while the C++ ones beside them run in parallel. Every Python object the
/// workers hold is released with the GIL taken.
#include "py_estimator.hpp"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>

#include "any_filter.hpp"
#include "bind.hpp"
#include "field_value.hpp"
#include "native_makers.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/sim/estimators.hpp"

namespace py = pybind11;

namespace nlosloc::bind {

namespace {

/// The objects a (name, filter) entry may hold, for the messages.
constexpr const char* kNativeTypes =
    "filters.Ekf, Ukf or UkfAugmented; rbpf.Iukf, Rbpf or ParticleFilter; mitigation.QpBiasEkf or "
    "BiasAugmentedEkf; snapshot.MleLos, Chen, Cong or Urruela";

/// A contiguous vector as a new numpy array (the estimator may keep it: it owns its copy).
py::array_t<double> vector_array(const Eigen::Ref<const VecX>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

/// obj.<method>, which must be callable; TypeError naming the estimator otherwise.
py::object method(const py::object& obj, const char* m, const std::string& name, const char* signature) {
  if (py::hasattr(obj, m)) {
    py::object f = obj.attr(m);
    if (PyCallable_Check(f.ptr()) != 0) return f;
  }
  throw py::type_error("estimators: the factory of '" + name + "' returned " + describe(obj) +
                       ", which has no method " + signature);
}

/// sim::Estimator over a Python object with reset(draw, rng), step(k, y, o) and optionally
/// sight_estimate(). Built and destroyed on one worker thread; every call takes the GIL.
class PythonEstimator final : public sim::Estimator {
 public:
  /// With the GIL held.
  PythonEstimator(std::string name, const py::object& obj, Eigen::Index dim, Eigen::Index anchors,
                  int conditions)
      : name_(std::move(name)),
        obj_(obj),
        reset_(method(obj, "reset", name_, "reset(draw, rng)")),
        step_(method(obj, "step", name_, "step(k, y, o)")),
        dim_(dim),
        anchors_(anchors),
        conditions_(conditions) {
    if (py::hasattr(obj, "sight_estimate"))
      sight_ = method(obj, "sight_estimate", name_, "sight_estimate() (or no attribute of that name)");
    // Keeps this (worker) thread's Python thread state until the destructor: without it every call's
    // gil_scoped_acquire made and deleted one.
    py::gil_scoped_acquire keep;
    keep.inc_ref();
  }
  ~PythonEstimator() override {
    py::gil_scoped_acquire gil;  // the members' destructors would otherwise drop them without it
    sight_ = py::object();
    step_ = py::object();
    reset_ = py::object();
    obj_ = py::object();
    if (std::this_thread::get_id() == owner_) gil.dec_ref();  // the constructor's inc_ref (same thread state)
  }
  PythonEstimator(const PythonEstimator&) = delete;
  PythonEstimator& operator=(const PythonEstimator&) = delete;

  std::string name() const override { return name_; }

  /// reset(draw, rng): the draw as nlosloc.sim.draw() returns it, and a copy of the estimator's generator
  /// Rng(estimator_seed(seed, name), run), which nothing else draws from.
  void reset(const sim::Draw& d, Rng& rng) override {
    py::gil_scoped_acquire gil;
    reset_(draw_to_dict(d), py::cast(rng, py::return_value_policy::copy));
  }

  void step(int k, const Eigen::Ref<const VecX>& y, const Eigen::Ref<const VecX>& o,
            Eigen::Ref<VecX> position_out) override {
    py::gil_scoped_acquire gil;
    const py::object r = step_(k, vector_array(y), vector_array(o));
    const auto a = nlosloc::bind::real_array(r, ("estimators: step() of '" + name_ + "'").c_str());
    if (!a || a.ndim() != 1 || a.size() != dim_)
      throw py::value_error("estimators: step() of '" + name_ + "' returned " + describe(r, a) +
                            "; expected the " + std::to_string(dim_) + " coordinates of the position");
    std::copy(a.data(), a.data() + a.size(), position_out.data());
  }

  bool estimates_sight() const override { return static_cast<bool>(sight_); }

  void sight_estimate(Eigen::Ref<VecXi> out) const override {
    py::gil_scoped_acquire gil;
    const py::object r = sight_();
    const auto raw = py::array::ensure(r);
    using IntArray = py::array_t<long long, py::array::c_style | py::array::forcecast>;
    IntArray a;
    bool ok = false;
    if (raw) {
      const char kind = raw.dtype().kind();
      if (kind == 'i' || kind == 'u' || kind == 'b') {  // no float silently truncated
        a = IntArray::ensure(raw);
        ok = a && a.ndim() == 1 && a.size() == anchors_;
      }
    }
    if (!ok)
      throw py::value_error("estimators: sight_estimate() of '" + name_ + "' returned " + describe(r, raw) +
                            "; expected " + std::to_string(anchors_) +
                            " integer conditions (0 = LOS), one per anchor");
    for (py::ssize_t b = 0; b < a.size(); ++b) {
      const long long v = a.data()[b];
      if (v < 0 || v >= conditions_)  // as CustomScenario's sight: a condition the scenario has
        throw py::value_error("estimators: sight_estimate() of '" + name_ + "' returned condition " +
                              std::to_string(v) + " for anchor " + std::to_string(b) +
                              "; expected an integer in [0, " + std::to_string(conditions_) + ") (0 = LOS)");
      out[b] = static_cast<int>(v);
    }
  }

 private:
  std::string name_;
  py::object obj_, reset_, step_, sight_;
  Eigen::Index dim_, anchors_;
  int conditions_;  ///< N_z of the scenario: sight_estimate() values in [0, N_z)
  std::thread::id owner_ = std::this_thread::get_id();  // the runner makes and drops it on one worker
};

/// An Ekf, Ukf or UkfAugmented of nlosloc.filters as a GaussianFilterEstimator (the draw's initial belief at
/// t = 0, update at step 0, predict + update after). Null when `h` is no such filter.
template <template <class> class F>
NativeMaker gaussian_maker(const py::handle& h, const std::string& name, sim::SightPolicy sight,
                           const sim::Scenario& s) {
  if (!py::isinstance<AnyFilter<F>>(h)) return nullptr;
  auto proto = std::make_shared<const AnyFilter<F>>(h.cast<const AnyFilter<F>&>());
  proto->visit([&](const auto& f) {
    check_fit(name, "filter", std::decay_t<decltype(f)>::kDim, f.measurements().rows(), -1, f.motion().dt(),
              s);
  });
  return [name, proto, sight] {
    return proto->visit([&](const auto& f) -> std::unique_ptr<sim::Estimator> {
      return sim::make_filter_estimator(name, f, sight);
    });
  };
}

/// The native estimator of any object above, or null. `sight` (the entry's third item) goes with the
/// Gaussian filters only: TypeError naming the estimator when given with any other (they estimate sight).
NativeMaker any_native_maker(const py::handle& h, const std::string& name,
                             const std::optional<sim::SightPolicy>& sight, const sim::Scenario& s) {
  const sim::SightPolicy gs = sight.value_or(sim::SightPolicy::kAssumeLos);
  if (NativeMaker m = gaussian_maker<EkfT>(h, name, gs, s)) return m;
  if (NativeMaker m = gaussian_maker<UkfT>(h, name, gs, s)) return m;
  if (NativeMaker m = gaussian_maker<UkfAugT>(h, name, gs, s)) return m;
  NativeMaker m = rbpf_maker(h, name, s);
  if (!m) m = mitigation_maker(h, name, s);
  if (!m) m = snapshot_maker(h, name, s);
  if (m && sight)
    throw py::type_error("estimators: '" + name + "' is " + describe(h) +
                         "; a sight policy goes with an Ekf, Ukf or UkfAugmented of nlosloc.filters only");
  return m;
}

/// The sight policy of a native filter's entry: "assume_los" or "oracle".
sim::SightPolicy sight_policy(const py::handle& h, std::size_t i) {
  if (py::isinstance<py::str>(h)) {
    const auto v = h.cast<std::string>();
    if (v == "assume_los") return sim::SightPolicy::kAssumeLos;
    if (v == "oracle") return sim::SightPolicy::kOracle;
  }
  throw py::value_error("estimators[" + std::to_string(i) +
                        "]: expected the sight policy 'assume_los' or 'oracle' as third item, got " +
                        py::repr(h).cast<std::string>());
}

/// A registered estimator of scenario s.
sim::EstimatorSpec registered(const sim::Registry& reg, const sim::Scenario& s, const std::string& n) {
  return {n, reg.estimator(s.name(), n)};
}

}  // namespace

/// "estimators: the <what> of '<name>' " for the messages.
std::string who(const std::string& name, const char* what) {
  return std::string("estimators: the ") + what + " of '" + name + "' ";
}

/// ValueError naming the estimator when an object's state size, measurement rows, anchors or time step
/// differ from scenario s's (dt NaN: not checked, the snapshot solvers have none; anchors -1 likewise).
void check_fit(const std::string& name, const char* what, int n, Eigen::Index rows, Eigen::Index anchors,
               double dt, const sim::Scenario& s) {
  const std::string w = who(name, what);
  if (n != s.state_dim())
    throw py::value_error(w + "has a state of " + std::to_string(n) + " components; scenario " + s.name() +
                          " has " + std::to_string(s.state_dim()));
  if (rows != s.measurements().rows())
    throw py::value_error(w + "has " + std::to_string(rows) + " measurement rows; scenario " + s.name() +
                          " has " + std::to_string(s.measurements().rows()));
  if (anchors >= 0 && anchors != s.anchors().rows())
    throw py::value_error(w + "has " + std::to_string(anchors) + " anchors; scenario " + s.name() + " has " +
                          std::to_string(s.anchors().rows()));
  if (!std::isnan(dt) && !(std::abs(dt - s.dt()) <= 1e-12 * std::max(1.0, std::abs(s.dt()))))
    throw py::value_error(w + "predicts over dt = " + float_repr(dt) + " s; scenario " + s.name() +
                          " samples every " + float_repr(s.dt()) + " s");
}

py::dict draw_to_dict(sim::Draw d) {
  py::dict r;
  r["scenario"] = d.scenario;
  r["case"] = d.case_name;
  r["case_index"] = d.case_index;
  r["seed"] = d.seed;
  r["run"] = d.run;
  r["dt"] = d.dt;
  r["states"] = py::cast(std::move(d.states));
  r["positions"] = py::cast(std::move(d.positions));
  r["y"] = py::cast(std::move(d.y));
  r["sight"] = py::cast(std::move(d.sight));
  r["quality"] = py::cast(std::move(d.quality));
  r["initial_mean"] = py::cast(std::move(d.initial_mean));
  r["initial_cov"] = py::cast(std::move(d.initial_cov));
  return r;
}

std::vector<sim::EstimatorSpec> estimator_specs(const sim::Registry& reg,
                                                const std::shared_ptr<sim::Scenario>& scenario,
                                                const std::optional<py::sequence>& estimators) {
  const sim::Scenario& s = *scenario;
  std::vector<sim::EstimatorSpec> specs;
  const bool has_registered = reg.has_scenario(s.name());
  if (estimators && py::len(*estimators) == 0)  // as sim::check_estimator_specs; None means all registered
    throw py::value_error(
        "estimators: expected at least one estimator, got an empty list (None: every estimator registered "
        "for the scenario)");
  if (!estimators) {
    if (!has_registered)
      throw py::value_error(
          "estimators: scenario '" + s.name() +
          "' has no registered estimators; give Python estimators (name, factory) or filters "
          "(name, filter)");
    for (const auto& n : reg.estimators(s.name())) specs.push_back(registered(reg, s, n));
    return specs;
  }
  if (py::isinstance<py::str>(*estimators) || py::isinstance<py::bytes>(*estimators))
    throw py::type_error(
        "estimators: expected a list of estimator names and (name, factory) pairs, got a single string");
  // The factories get the scenario as the caller's Python object (custom parameters included).
  const SharedObject scen = share(py::cast(scenario));
  const Eigen::Index dim = s.space_dim(), anchors = s.anchors().rows();
  const py::sequence& seq = *estimators;
  for (std::size_t i = 0; i < py::len(seq); ++i) {
    const py::object e = seq[i];
    if (py::isinstance<py::str>(e)) {
      if (!has_registered)
        throw py::value_error("estimators[" + std::to_string(i) + "]: scenario '" + s.name() +
                              "' has no registered estimators, got the name " +
                              py::repr(e).cast<std::string>());
      specs.push_back(registered(reg, s, e.cast<std::string>()));
      continue;
    }
    const bool tuple_like = py::isinstance<py::tuple>(e) || py::isinstance<py::list>(e);
    const std::size_t len = tuple_like ? py::len(e) : 0;
    const bool named = (len == 2 || len == 3) && py::isinstance<py::str>(e[py::int_(0)]);
    const bool callable = named && PyCallable_Check(e[py::int_(1)].ptr()) != 0;
    const std::optional<sim::SightPolicy> sight =
        named && len == 3 ? std::optional<sim::SightPolicy>(sight_policy(e[py::int_(2)], i)) : std::nullopt;
    const std::string name = named ? e[py::int_(0)].cast<std::string>() : std::string();
    if (named && !callable) {  // (name, filter[, sight]): a filter object of nlosloc.filters, run natively
      if (NativeMaker make = any_native_maker(e[py::int_(1)], name, sight, s)) {
        specs.push_back({name, [make](const sim::Scenario&, int) { return make(); }});
        continue;
      }
    }
    if (!callable)
      throw py::type_error(
          "estimators[" + std::to_string(i) +
          "]: expected a registered estimator name (str), a (name, factory[, sight]) tuple with "
          "a callable factory(scenario, case_index), or a (name, filter[, sight]) tuple with a filter "
          "(" +
          std::string(kNativeTypes) + "), got " + py::repr(e).cast<std::string>());
    const SharedObject factory = share(e[py::int_(1)]);
    specs.push_back({name,
                     [name, factory, scen, dim, anchors, sight](const sim::Scenario& sc,
                                                                int c) -> std::unique_ptr<sim::Estimator> {
                       py::gil_scoped_acquire gil;
                       const py::object obj = (*factory)(*scen, c);
                       if (obj.is_none())
                         throw py::type_error("estimators: the factory of '" + name +
                                              "' returned None; expected an estimator object");
                       // A filter of nlosloc.filters runs natively (a factory pickles where a filter does
                       // not: montecarlo.run(executor=...)).
                       if (NativeMaker make = any_native_maker(obj, name, sight, sc)) return make();
                       if (sight)
                         throw py::type_error(
                             "estimators: the factory of '" + name +
                             "' returned a Python estimator; a sight policy goes with an Ekf, Ukf or "
                             "UkfAugmented of nlosloc.filters only");
                       return std::make_unique<PythonEstimator>(name, obj, dim, anchors,
                                                                sc.measurements().num_conditions());
                     }});
  }
  return specs;
}

}  // namespace nlosloc::bind
