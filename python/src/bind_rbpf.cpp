/// \file bind_rbpf.cpp
/// nlosloc.rbpf: Rao-Blackwellized particle filters (Huerta Tables IV and V) with merge/select, the joint
/// particle filter, the merge and resampling helpers, and the IUKF (Table VI; exposed here as
/// nlosloc.rbpf.Iukf because it needs the situation types). The C++ filters are templates over the motion
/// model; each Python class holds a std::variant over the motion models (type erasure at the filter level).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "any_rbpf.hpp"
#include "batch.hpp"
#include "bind.hpp"
#include "field_value.hpp"
#include "int_arg.hpp"
#include "motion_arg.hpp"
#include "native_makers.hpp"
#include "nlosloc/filters/iukf.hpp"
#include "nlosloc/rbpf/pf.hpp"
#include "nlosloc/rbpf/rbpf.hpp"
#include "nlosloc/sim/h1.hpp"
#include "params_field.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_rbpf_cpp {
using namespace nlosloc::rbpf;
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

namespace {
using bind::AnyIukf;
using bind::AnyPf;
using bind::AnyRbpf;
using bind::IukfBox;
using bind::to_gaussian;

/// Runs f.step over the rows of Y, O (GIL released), every row checked first (batch.hpp); returns the
/// per-step estimates.
template <class A, class Step>
py::dict run_batch(A& a, const Eigen::Ref<const RowMat>& Y, const Eigen::Ref<const RowMat>& O, Step&& step) {
  NLOSLOC_ENSURE(Y.rows() == O.rows(), "Y, O: expected the same number of steps (rows), got " +
                                           std::to_string(Y.rows()) + " and " + std::to_string(O.rows()));
  const Eigen::Index T = Y.rows();
  int n = 0, B = 0, nz = 0;
  a.visit([&](auto& f) {
    n = static_cast<int>(f.estimate().size());
    B = static_cast<int>(f.situation_probabilities().rows());
    nz = static_cast<int>(f.situation_probabilities().cols());
    bind::check_steps(T, [&](Eigen::Index k) { f.check_inputs(Y.row(k).transpose(), O.row(k).transpose()); });
  });
  py::array_t<double> mean({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(n)});
  py::array_t<double> cov(
      {static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(n)});
  py::array_t<double> prob(
      {static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(B), static_cast<py::ssize_t>(nz)});
  py::array_t<double> ll(static_cast<py::ssize_t>(T));
  auto mm = mean.mutable_unchecked<2>();
  auto cm = cov.mutable_unchecked<3>();
  auto pm = prob.mutable_unchecked<3>();
  auto lm = ll.mutable_unchecked<1>();
  {
    py::gil_scoped_release release;
    a.visit([&](auto& f) {
      bind::run_steps(T, [&](Eigen::Index t) {
        lm(t) = step(f, VecX(Y.row(t).transpose()), VecX(O.row(t).transpose()));
        for (int i = 0; i < n; ++i) {
          mm(t, i) = f.estimate()(i);
          for (int j = 0; j < n; ++j) cm(t, i, j) = f.covariance()(i, j);
        }
        for (int b = 0; b < B; ++b)
          for (int z = 0; z < nz; ++z) pm(t, b, z) = f.situation_probabilities()(b, z);
      });
    });
  }
  py::dict d;
  d["mean"] = mean;
  d["cov"] = cov;
  d["situation_probabilities"] = prob;
  d["log_likelihood"] = ll;
  return d;
}

/// Accessors shared by the RBPF, the PF and the IUKF wrappers.
template <class A, class C>
void summary_methods(C& c) {
  c.def_property_readonly(
       "estimate", [](const A& a) { return a.visit([](const auto& f) { return VecX(f.estimate()); }); },
       "State estimate (n,) (Huerta eq. 28 for the RBPF).")
      .def_property_readonly(
          "covariance",
          [](const A& a) { return a.visit([](const auto& f) { return MatX(f.covariance()); }); },
          "Covariance (n, n) of the posterior (moment-matched mixture, eq. 27).")
      .def_property_readonly(
          "situation_probabilities",
          [](const A& a) { return a.visit([](const auto& f) { return MatX(f.situation_probabilities()); }); },
          "(B, N_z) P(s_b = z | data).")
      .def(
          "sight_estimate",
          [](const A& a) { return a.visit([](const auto& f) { return VecXi(f.sight_estimate()); }); },
          "Most probable condition per anchor (B,).")
      .def_property_readonly(
          "time", [](const A& a) { return a.visit([](const auto& f) { return f.time(); }); },
          "Time of the estimate (s).")
      .def(
          "belief",
          [](const A& a) {
            return a.visit([](const auto& f) {
              const auto g = f.belief();
              return py::make_tuple(VecX(g.mean), MatX(g.cov));
            });
          },
          "The Gaussian summary as a tuple (mean (n,), cov (n, n)).")
      .def(
          "check_inputs",
          [](const A& a, const bind::VecArg& y_in, const bind::VecArg& o_in) {
            const VecX y = y_in.get("y"), o = o_in.get("o");
            a.visit([&](const auto& f) { f.check_inputs(y, o); });
          },
          py::arg("y"), py::arg("o"),
          "Raises the ValueError a step with y (m,) and o (B,) would raise, changing nothing (run() checks "
          "every row this way before its first step).");
}

/// Accessors shared by Rbpf and ParticleFilter: options, models, reset, save and restore.
template <class A, class Snapshot, class C>
void particle_filter_methods(C& c) {
  c.def(
       "save", [](const A& a) { return a.visit([](const auto& f) { return f.save(); }); },
       "A snapshot of everything the next step depends on (the joint PF's: its random generators too): "
       "restore() of it into a filter of this class with the same models and options makes that one "
       "step on exactly as this one.")
      .def(
          "restore", [](A& a, const Snapshot& s) { a.visit([&](auto& f) { f.restore(s); }); },
          py::arg("snapshot"),
          "Sets the filter to a snapshot (checked first: ValueError naming the field, nothing changed).")
      .def_property_readonly(
          "step_index", [](const A& a) { return a.visit([](const auto& f) { return f.step_index(); }); },
          "Steps taken since the last reset.")
      .def_property_readonly(
          "options", [](const A& a) { return a.visit([](const auto& f) { return f.options(); }); },
          "The settings (a copy).")
      .def_property_readonly(
          "measurements", [](const A& a) { return a.visit([](const auto& f) { return f.measurements(); }); },
          "The measurement stack (a copy).")
      .def_property_readonly(
          "motion", [](const A& a) { return a.visit([](const auto& f) { return py::cast(f.motion()); }); },
          "The motion model (a copy).")
      .def_property_readonly(
          "sight_process",
          [](const A& a) { return a.visit([](const auto& f) { return f.sight_process(); }); },
          "The situation.SightProcess it was built with (a copy).")
      .def_property_readonly(
          "quality", [](const A& a) { return a.visit([](const auto& f) { return f.quality(); }); },
          "The situation.QualityModel it was built with (a copy).")
      .def(
          "reset",
          [](A& a, const bind::VecArg& mean_in, const bind::MatArg& cov_in,
             const bind::StrictArg<double>& t0_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const double t0 = t0_in.get("t0");
            a.visit([&](auto& f) {
              constexpr int N = std::decay_t<decltype(f)>::N;
              f.reset(to_gaussian<N>(mean, cov), t0);
            });
          },
          py::arg("mean"), py::arg("cov"), py::arg("t0") = 0.0,
          "Restarts from N(mean, cov) at time t0 (validated; a rejected call changes nothing).");
}

/// py::init of a wrapper A over the motion models from (motion, measurements, sight, quality, mean, cov,
/// extra, t0), the arguments of Rbpf, ParticleFilter and Iukf: make(mo, meas, sight, quality, N(mean,
/// cov), extra, t0) builds the filter for the motion model mo.
template <class A, class Extra, class Make>
auto sight_filter_init(Make make) {
  return py::init([make](const py::object& motion, const MeasurementStack& meas,
                         const situation::SightProcess& sight, const situation::QualityModel& quality,
                         const bind::VecArg& mean_in, const bind::MatArg& cov_in, const Extra& extra,
                         const bind::StrictArg<double>& t0_in) {
    const VecX mean = mean_in.get("mean");
    const MatX cov = cov_in.get("cov");
    const double t0 = t0_in.get("t0");
    return A(motion, [&](const auto& mo) {
      using Mo = std::decay_t<decltype(mo)>;
      return make(mo, meas, sight, quality, to_gaussian<Mo::kDim>(mean, cov), extra, t0);
    });
  });
}

/// Constructor, summary accessors, step and run of a joint filter wrapper A (AnyRbpf: Filter = Rbpf,
/// AnyPf: ParticleFilter), Filter<Mo> built for the motion model passed, in this order (the stubs list
/// them so).
template <class A, template <class...> class Filter, class Options, class C>
void joint_filter_core(C& c, const char* options_repr, const char* step_doc, const char* run_doc) {
  c.def(sight_filter_init<A, Options>([](const auto& mo, const auto&... args) {
          return std::make_unique<Filter<std::decay_t<decltype(mo)>>>(mo, args...);
        }),
        py::arg("motion"), py::arg("measurements"), py::arg("sight"), py::arg("quality"), py::arg("mean"),
        py::arg("cov"), py::arg_v("options", Options(), options_repr), py::arg("t0") = 0.0);
  summary_methods<A>(c);
  c.def(
       "step",
       [](A& a, const bind::VecArg& y_in, const bind::VecArg& o_in) {
         const VecX y = y_in.get("y"), o = o_in.get("o");
         py::gil_scoped_release rel;
         return a.visit([&](auto& f) { return f.step(y, o); });
       },
       py::arg("y"), py::arg("o"), step_doc)
      .def(
          "run",
          [](A& a, const bind::RowMatArg& Y_in, const bind::RowMatArg& O_in) {
            const RowMat Y = Y_in.get("Y");
            const RowMat O = O_in.get("O");
            return run_batch(
                a, Y, O, [](auto& f, const VecX& y, const VecX& o) { return f.step(y, o).log_likelihood; });
          },
          py::arg("Y"), py::arg("O"), run_doc);
}

/// Log weights of the merge and prune helpers: finite or -inf (a particle ruled out), never NaN or +inf.
void check_log_weights(const VecX& logw) {
  NLOSLOC_ENSURE(are_log_weights(logw),
                 "logw: expected log weights that are finite or -inf (no NaN, no +inf)");
}

/// Per-anchor log factors A (B, N_z) of the offspring enumerations: B, N_z >= 1, no NaN or +inf (-inf: a
/// condition ruled out).
void check_factors(const MatX& A) {
  NLOSLOC_ENSURE(A.rows() >= 1 && A.cols() >= 1, "A: expected (B, N_z) log factors with B, N_z >= 1, got (" +
                                                     std::to_string(A.rows()) + ", " +
                                                     std::to_string(A.cols()) + ")");
  for (Eigen::Index b = 0; b < A.rows(); ++b)
    for (Eigen::Index z = 0; z < A.cols(); ++z)
      NLOSLOC_ENSURE(!std::isnan(A(b, z)) && A(b, z) != std::numeric_limits<double>::infinity(),
                     "A: expected log factors that are finite or -inf, got " + std::to_string(A(b, z)) +
                         " at (" + std::to_string(b) + ", " + std::to_string(z) + ")");
}

/// (keys, sums) of an enumeration of A's situation vectors, at most `limit` (the arrays are returned, so
/// their size is capped: 2^24 from Python).
template <class Run>
py::tuple enumerated(const MatX& A, std::uint64_t limit, Run&& run) {
  check_factors(A);
  NLOSLOC_ENSURE(limit >= 1, "limit: expected an integer >= 1, got 0");
  const std::uint64_t total = situation_count(static_cast<int>(A.cols()), static_cast<int>(A.rows()));
  const std::uint64_t count = total == 0 ? limit : std::min(total, limit);
  constexpr std::uint64_t kMax = std::uint64_t{1} << 24;
  NLOSLOC_ENSURE(count <= kMax, "limit: the call would return " + std::to_string(count) +
                                    " situation vectors; expected at most 2^24 (lower limit)");
  std::vector<std::uint64_t> keys;
  std::vector<double> sums;
  keys.reserve(static_cast<std::size_t>(count));
  sums.reserve(static_cast<std::size_t>(count));
  {
    py::gil_scoped_release nogil;
    run([&](std::uint64_t key, double sum) {
      keys.push_back(key);
      sums.push_back(sum);
    });
  }
  return py::make_tuple(py::array_t<std::uint64_t>(static_cast<py::ssize_t>(keys.size()), keys.data()),
                        py::array_t<double>(static_cast<py::ssize_t>(sums.size()), sums.data()));
}
}  // namespace

void define_module(py::module_& m) {
  py::enum_<RbpfVariant>(m, "RbpfVariant", "Order of the RBPF iteration.")
      .value("Classical", RbpfVariant::kClassical, "Table IV: a UKF for every child")
      .value("Reordered", RbpfVariant::kReordered, "Table V: merge/select first, M UKFs");
  py::enum_<PfResampling>(m, "PfResampling", "Selection step of the joint PF.")
      .value("Systematic", PfResampling::kSystematic, "systematic resampling when ESS < threshold M")
      .value("MergeSelect", PfResampling::kMergeSelect,
             "bucketed merge (eqs. 29-30) then systematic resampling");

  py::class_<RbpfOptions>(m, "RbpfOptions", "Settings of Rbpf.")
      .def(py::init<>())
      .def(py::init([](const bind::StrictArg<RbpfVariant>& variant, const bind::StrictArg<int>& num_particles,
                       const bind::UInt64Arg& max_offspring, const bind::StrictArg<bool>& merge,
                       const bind::StrictArg<double>& merge_threshold, const bind::StrictArg<int>& threads,
                       const bind::StrictArg<SigmaScheme>& scheme,
                       const bind::StrictArg<NoiseForm>& noise_form) {
             return RbpfOptions{variant.get("variant"),
                                num_particles.get("num_particles"),
                                max_offspring.get("max_offspring"),
                                merge.get("merge"),
                                merge_threshold.get("merge_threshold"),
                                threads.get("threads"),
                                scheme.get("scheme"),
                                noise_form.get("noise_form")};
           }),
           py::arg("variant") = RbpfVariant::kReordered, py::arg("num_particles") = 16,
           py::arg("max_offspring") = 4096, py::arg("merge") = true, py::arg("merge_threshold") = -1.0,
           py::arg("threads") = 1, py::arg_v("scheme", SigmaScheme::scaled(), "SigmaScheme.scaled()"),
           py::arg("noise_form") = NoiseForm::kAdditive)
      .def_property("variant", bind::field_get<&RbpfOptions::variant>(),
                    bind::field_set<&RbpfOptions::variant>("variant"))
      .def_property("num_particles", bind::field_get<&RbpfOptions::num_particles>(),
                    bind::field_set<&RbpfOptions::num_particles>("num_particles"),
                    "M, particles propagated (>= 1).")
      .def_property(
          "max_offspring", [](const RbpfOptions& o) { return o.max_offspring; },
          [](RbpfOptions& o, const bind::UInt64Arg& v) { o.max_offspring = v.get("max_offspring"); },
          "Children per particle; above N_z^B the best ones by prior x quality (bounded).")
      .def_property("merge", bind::field_get<&RbpfOptions::merge>(),
                    bind::field_set<&RbpfOptions::merge>("merge"))
      .def_property("merge_threshold", bind::field_get<&RbpfOptions::merge_threshold>(),
                    bind::field_set<&RbpfOptions::merge_threshold>("merge_threshold"),
                    "d_min; negative: eq. (31).")
      .def_property("threads", bind::field_get<&RbpfOptions::threads>(),
                    bind::field_set<&RbpfOptions::threads>("threads"))
      .def_property("scheme", bind::field_get<&RbpfOptions::scheme>(),
                    bind::field_set<&RbpfOptions::scheme>("scheme"))
      .def_property("noise_form", bind::field_get<&RbpfOptions::noise_form>(),
                    bind::field_set<&RbpfOptions::noise_form>("noise_form"),
                    "UKF noise: Additive moments (default, one sigma set per parent) or Augmented "
                    "(Table III's noise sigma set, one sigma set per child).");

  py::class_<RbpfSnapshot>(m, "RbpfSnapshot",
                           "What an Rbpf carries from one step to the next (Rbpf.save / Rbpf.restore): a "
                           "checkpoint, and what pickling an Rbpf stores. Checked by Rbpf.restore.")
      .def(py::init([](const bind::StrictArg<Eigen::MatrixXi>& situations, const bind::MatArg& means,
                       const bind::StrictArg<std::vector<MatX>>& covs, const bind::VecArg& log_weights,
                       const bind::MatArg& situation_probabilities, const bind::VecArg& estimate,
                       const bind::MatArg& covariance, const bind::StrictArg<double>& time,
                       const bind::StrictArg<long>& step) {
             // braced initialisation reads the arguments in order, so the first bad one is named
             return RbpfSnapshot{situations.get("situations"),
                                 means.get("means"),
                                 covs.get("covs"),
                                 log_weights.get("log_weights"),
                                 situation_probabilities.get("situation_probabilities"),
                                 estimate.get("estimate"),
                                 covariance.get("covariance"),
                                 time.get("time"),
                                 step.get("step")};
           }),
           py::arg("situations"), py::arg("means"), py::arg("covs"), py::arg("log_weights"),
           py::arg("situation_probabilities"), py::arg("estimate"), py::arg("covariance"), py::arg("time"),
           py::arg("step"),
           "situations (P, B) condition indices, means (P, n), covs: P arrays (n, n) (or one (P, n, n)), "
           "log_weights (P,) normalised, situation_probabilities (B, N_z), estimate (n,), covariance (n, n), "
           "time (s), step (steps since the reset; 0: the next step draws from the initial sight).")
      .def_readonly("situations", &RbpfSnapshot::situations, "(P, B) condition indices (0 = LOS).")
      .def_readonly("means", &RbpfSnapshot::means, "(P, n) kinetic means (eq. 26).")
      .def_readonly("covs", &RbpfSnapshot::covs, "P covariances (n, n) (eq. 26).")
      .def_readonly("log_weights", &RbpfSnapshot::log_weights, "(P,) normalised log weights.")
      .def_readonly("situation_probabilities", &RbpfSnapshot::situation_probabilities, "(B, N_z).")
      .def_readonly("estimate", &RbpfSnapshot::estimate, "Eq. (28).")
      .def_readonly("covariance", &RbpfSnapshot::covariance, "Eq. (27), moment matched.")
      .def_readonly("time", &RbpfSnapshot::time)
      .def_readonly("step", &RbpfSnapshot::step);

  py::class_<RbpfStepInfo>(m, "RbpfStepInfo", "What one RBPF step reports.")
      .def_readonly("log_likelihood", &RbpfStepInfo::log_likelihood)
      .def_readonly("offspring", &RbpfStepInfo::offspring)
      .def_readonly("ukf_runs", &RbpfStepInfo::ukf_runs)
      .def_readonly("merged", &RbpfStepInfo::merged)
      .def_readonly("failures", &RbpfStepInfo::failures)
      .def_readonly("merge_threshold", &RbpfStepInfo::merge_threshold)
      .def_readonly("status", &RbpfStepInfo::status);

  py::class_<PfOptions>(m, "PfOptions", "Settings of ParticleFilter.")
      .def(py::init<>())
      .def(
          py::init(
              [](const bind::StrictArg<int>& num_particles, const bind::StrictArg<PfResampling>& resampling,
                 const bind::StrictArg<double>& ess_threshold, const bind::StrictArg<double>& merge_threshold,
                 const bind::StrictArg<int>& threads, const bind::UInt64Arg& seed) {
                return PfOptions{num_particles.get("num_particles"),
                                 resampling.get("resampling"),
                                 ess_threshold.get("ess_threshold"),
                                 merge_threshold.get("merge_threshold"),
                                 threads.get("threads"),
                                 seed.get("seed")};
              }),
          py::arg("num_particles") = 10000, py::arg("resampling") = PfResampling::kSystematic,
          py::arg("ess_threshold") = 0.5, py::arg("merge_threshold") = -1.0, py::arg("threads") = 1,
          py::arg("seed") = 0)
      .def_property("num_particles", bind::field_get<&PfOptions::num_particles>(),
                    bind::field_set<&PfOptions::num_particles>("num_particles"))
      .def_property("resampling", bind::field_get<&PfOptions::resampling>(),
                    bind::field_set<&PfOptions::resampling>("resampling"))
      .def_property("ess_threshold", bind::field_get<&PfOptions::ess_threshold>(),
                    bind::field_set<&PfOptions::ess_threshold>("ess_threshold"))
      .def_property("merge_threshold", bind::field_get<&PfOptions::merge_threshold>(),
                    bind::field_set<&PfOptions::merge_threshold>("merge_threshold"))
      .def_property("threads", bind::field_get<&PfOptions::threads>(),
                    bind::field_set<&PfOptions::threads>("threads"))
      .def_property(
          "seed", [](const PfOptions& o) { return o.seed; },
          [](PfOptions& o, const bind::UInt64Arg& v) { o.seed = v.get("seed"); });

  py::class_<PfSnapshot>(m, "PfSnapshot",
                         "What a ParticleFilter carries from one step to the next (ParticleFilter.save / "
                         "ParticleFilter.restore): a checkpoint, and what pickling a ParticleFilter stores. "
                         "Checked by ParticleFilter.restore.")
      .def(py::init([](const bind::MatArg& particles, const bind::StrictArg<Eigen::MatrixXi>& situations,
                       const bind::VecArg& log_weights, const bind::MatArg& situation_probabilities,
                       const bind::VecArg& estimate, const bind::MatArg& covariance,
                       const bind::StrictArg<double>& position_variance,
                       const std::vector<std::uint64_t>& generators, const bind::StrictArg<double>& time,
                       const bind::StrictArg<long>& step) {
             return PfSnapshot{particles.get("particles"),
                               situations.get("situations"),
                               log_weights.get("log_weights"),
                               situation_probabilities.get("situation_probabilities"),
                               estimate.get("estimate"),
                               covariance.get("covariance"),
                               position_variance.get("position_variance"),
                               generators,
                               time.get("time"),
                               step.get("step")};
           }),
           py::arg("particles"), py::arg("situations"), py::arg("log_weights"),
           py::arg("situation_probabilities"), py::arg("estimate"), py::arg("covariance"),
           py::arg("position_variance"), py::arg("generators"), py::arg("time"), py::arg("step"),
           "particles (n, M), situations (B, M) condition indices, log_weights (M,) normalised, "
           "situation_probabilities (B, N_z), estimate (n,), covariance (n, n), position_variance (eq. 31's "
           "input), generators (GENERATOR_WORDS words per thread, as save() gives them), time (s), step.")
      .def_readonly("particles", &PfSnapshot::particles, "(n, M) states.")
      .def_readonly("situations", &PfSnapshot::situations, "(B, M) condition indices (0 = LOS).")
      .def_readonly("log_weights", &PfSnapshot::log_weights, "(M,) normalised log weights.")
      .def_readonly("situation_probabilities", &PfSnapshot::situation_probabilities, "(B, N_z).")
      .def_readonly("estimate", &PfSnapshot::estimate, "Weighted mean after the last weighting.")
      .def_readonly("covariance", &PfSnapshot::covariance, "Weighted covariance after the last weighting.")
      .def_readonly("position_variance", &PfSnapshot::position_variance,
                    "Its position variance as the step computed it (eq. 31's d_min).")
      .def_readonly("generators", &PfSnapshot::generators,
                    "The threads' random generators: GENERATOR_WORDS 64-bit words each (opaque).")
      .def_readonly("time", &PfSnapshot::time)
      .def_readonly("step", &PfSnapshot::step)
      .attr("GENERATOR_WORDS") = PfSnapshot::kGeneratorWords;  // words per thread in generators

  py::class_<PfStepInfo>(m, "PfStepInfo", "What one PF step reports.")
      .def_readonly("log_likelihood", &PfStepInfo::log_likelihood)
      .def_readonly("ess", &PfStepInfo::ess)
      .def_readonly("resampled", &PfStepInfo::resampled)
      .def_readonly("merged", &PfStepInfo::merged);

  {
    using A = AnyRbpf;
    py::class_<A> c(m, "Rbpf",
                    "Rao-Blackwellized particle filter with UKF bank and merge/select (Huerta Sec. V-A/B).");
    joint_filter_core<A, Rbpf, RbpfOptions>(
        c, "RbpfOptions()", "One iteration with measurements y (m,) and quality statistics o (B,).",
        "step() over the rows of Y (T, m) and O (T, B), GIL released. Returns a dict of mean (T, n), cov "
        "(T, n, n), situation_probabilities (T, B, N_z), log_likelihood (T,).");
    c.def_property_readonly(
         "num_particles", [](const A& a) { return a.visit([](const auto& f) { return f.num_particles(); }); })
        .def_property_readonly("weights",
                               [](const A& a) { return a.visit([](const auto& f) { return f.weights(); }); })
        .def(
            "particle_mean",
            [](const A& a, bind::IndexArg i_arg) {
              const int i = i_arg.get("i");
              return a.visit([&](const auto& f) { return VecX(f.particle_mean(i)); });
            },
            py::arg("i"))
        .def(
            "particle_cov",
            [](const A& a, bind::IndexArg i_arg) {
              const int i = i_arg.get("i");
              return a.visit([&](const auto& f) { return MatX(f.particle_cov(i)); });
            },
            py::arg("i"))
        .def(
            "particle_situation",
            [](const A& a, bind::IndexArg i_arg) {
              const int i = i_arg.get("i");
              return a.visit([&](const auto& f) { return f.particle_situation(i); });
            },
            py::arg("i"))
        .def_property_readonly(
            "children_per_particle",
            [](const A& a) { return a.visit([](const auto& f) { return f.children_per_particle(); }); })
        .def(
            "log_weight",
            [](const A& a, bind::IndexArg i_arg) {
              const int i = i_arg.get("i");
              return a.visit([&](const auto& f) { return f.log_weight(i); });
            },
            py::arg("i"), "Normalised log weight of particle i.")
        .def_property_readonly(
            "num_anchors", [](const A& a) { return a.visit([](const auto& f) { return f.num_anchors(); }); })
        .def_property_readonly("num_conditions", [](const A& a) {
          return a.visit([](const auto& f) { return f.num_conditions(); });
        });
    particle_filter_methods<A, RbpfSnapshot>(c);
  }
  {
    using A = AnyPf;
    py::class_<A> c(m, "ParticleFilter",
                    "Joint bootstrap particle filter over (x, s) (Huerta Sec. VI-B, PF).");
    joint_filter_core<A, ParticleFilter, PfOptions>(c, "PfOptions()", nullptr, "As Rbpf.run.");
    c.def_property_readonly(
         "particles", [](const A& a) { return a.visit([](const auto& f) { return f.particles(); }); },
         "(n, M) particle states (a copy).")
        .def_property_readonly(
            "situations", [](const A& a) { return a.visit([](const auto& f) { return f.situations(); }); })
        .def_property_readonly(
            "log_weights",
            [](const A& a) { return a.visit([](const auto& f) { return VecX(f.log_weights()); }); })
        .def_property_readonly(
            "num_particles",
            [](const A& a) { return a.visit([](const auto& f) { return f.num_particles(); }); })
        .def_property_readonly(
            "uses_avx2", [](const A& a) { return a.visit([](const auto& f) { return f.uses_avx2(); }); },
            "Whether the pass runs its AVX2 build: a portable x86-64 build on a CPU with AVX2, with "
            "NLOSLOC_NO_AVX2 unset (or '0') in the environment when the filter was built. Either way a "
            "step's "
            "result is the same bit for bit.");
    particle_filter_methods<A, PfSnapshot>(c);
  }
  {
    using A = AnyIukf;
    py::class_<A> c(
        m, "Iukf",
        "Improved UKF (Huerta Table VI, N_z conditions as Grisales eqs. 36-37): per-anchor forward filter "
        "on the quality statistics, one noise set per condition weighted by its probabilities.");
    c.def(sight_filter_init<A, SigmaScheme>([](const auto& mo, const MeasurementStack& meas,
                                               const situation::SightProcess& sight,
                                               const situation::QualityModel& quality, const auto& belief,
                                               const SigmaScheme& scheme, double t0) {
            return std::make_unique<IukfBox<std::decay_t<decltype(mo)>>>(
                mo, meas, belief, situation::ForwardFilter(sight, quality), scheme, t0);
          }),
          py::arg("motion"), py::arg("measurements"), py::arg("sight"), py::arg("quality"), py::arg("mean"),
          py::arg("cov"), py::arg_v("scheme", SigmaScheme::scaled(), "SigmaScheme.scaled()"),
          py::arg("t0") = 0.0);
    summary_methods<A>(c);
    bind::def_set_belief<A>(c);
    c.def(
         "step",
         [](A& a, const bind::VecArg& y_in, const py::object& o, const py::object& sight) {
           const VecX y = y_in.get("y");
           NLOSLOC_ENSURE(o.is_none() != sight.is_none(),
                          "o, sight: expected exactly one of the quality statistics o or a known sight");
           if (!o.is_none()) {
             const VecX ov = bind::to_vector(o, "o");
             return a.visit([&](auto& f) { return f.step_quality(y, ov); });
           }
           const VecXi s = bind::to_sight(sight);
           return a.visit([&](auto& f) { return f.step(y, s); });
         },
         py::arg("y"), py::arg("o") = py::none(), py::kw_only(), py::arg("sight") = py::none(),
         "With o (B,): step_quality(y, o). With sight= (B,) ints: the C++ step(y, sight), a known "
         "situation (one-hot probabilities: the plain UKF). Returns a StepResult.")
        .def(
            "step_quality",
            [](A& a, const bind::VecArg& y_in, const bind::VecArg& o_in) {
              const VecX y = y_in.get("y"), o = o_in.get("o");
              return a.visit([&](auto& f) { return f.step_quality(y, o); });
            },
            py::arg("y"), py::arg("o"),
            "predict, forward filter with o (B,), update with y (m,); a rejected call changes nothing. "
            "Returns a StepResult.")
        .def_property_readonly(
            "forward",
            [](A& a) -> situation::ForwardFilter& {
              return a.visit([](auto& f) -> situation::ForwardFilter& { return f.forward(); });
            },
            py::return_value_policy::reference_internal, "The forward filter of the sight (not a copy).")
        .def_property_readonly(
            "measurements",
            [](const A& a) { return a.visit([](const auto& f) { return f.measurements(); }); },
            "The measurement stack (a copy).")
        .def_property_readonly(
            "scheme", [](const A& a) { return a.visit([](const auto& f) { return f.scheme(); }); },
            "The sigma-point scheme.")
        .def_property_readonly(
            "motion", [](const A& a) { return a.visit([](const auto& f) { return py::cast(f.motion()); }); },
            "The motion model (a copy).")
        .def_property_readonly(
            "dim",
            [](const A& a) { return a.visit([](const auto& f) { return std::decay_t<decltype(f)>::kDim; }); },
            "Size n of the state.")
        .def("predict", [](A& a) { a.visit([](auto& f) { f.predict(); }); })
        .def(
            "update_with_probabilities",
            [](A& a, const bind::VecArg& y_in, const bind::MatArg& gamma_in) {
              const MatX gamma = gamma_in.get("gamma");
              const VecX y = y_in.get("y");
              return a.visit([&](auto& f) { return f.update_with_probabilities(y, gamma); });
            },
            py::arg("y"), py::arg("gamma"), "Update with explicit (B, N_z) condition probabilities.")
        .def(
            "run",
            [](A& a, const bind::RowMatArg& Y_in, const bind::RowMatArg& O_in) {
              const RowMat Y = Y_in.get("Y");
              const RowMat O = O_in.get("O");
              return run_batch(a, Y, O, [](auto& f, const VecX& y, const VecX& o) {
                return f.step_quality(y, o).log_likelihood;
              });
            },
            py::arg("Y"), py::arg("O"), "As Rbpf.run.")
        .def_property_readonly(
            "mean", [](const A& a) { return a.visit([](const auto& f) { return VecX(f.mean()); }); })
        .def_property_readonly(
            "cov", [](const A& a) { return a.visit([](const auto& f) { return MatX(f.cov()); }); });
  }

  m.def("default_merge_threshold",
        bind::strict_fn(&default_merge_threshold, "position_variance", "num_particles"),
        py::arg("position_variance"), py::arg("num_particles"), "d_min = sigma^2 / (10 M), Huerta eq. (31).");
  m.def(
      "merge_greedy",
      [](const std::vector<bind::UInt64Arg>& key_args, const bind::MatArg& means_in,
         const bind::VecArg& logw_in, const bind::StrictArg<double>& d_min_in,
         const bind::StrictArg<bool>& with_pairs_in, const bind::StrictArg<int>& threads_in) -> py::tuple {
        const MatX means = means_in.get("means");
        VecX logw = logw_in.get("logw");
        std::vector<std::uint64_t> keys(key_args.size());
        for (std::size_t i = 0; i < keys.size(); ++i)
          keys[i] = key_args[i].get(("keys[" + std::to_string(i) + "]").c_str());
        NLOSLOC_ENSURE(
            static_cast<Eigen::Index>(keys.size()) == means.cols() && logw.size() == means.cols(),
            "keys, means, logw: expected one key, one mean column and one log weight per particle");
        nlosloc::detail::ensure_finite(means, "means");
        check_log_weights(logw);
        const double d_min = d_min_in.get("d_min");
        const bool with_pairs = with_pairs_in.get("with_pairs");
        const int threads = threads_in.get("threads");
        nlosloc::detail::ensure_nonnegative(d_min, "d_min");
        NLOSLOC_ENSURE(threads >= 1, "threads: expected an integer >= 1, got " + std::to_string(threads));
        auto close = [&](int a, int b) { return (means.col(a) - means.col(b)).norm() < d_min; };
        if (threads > 1) {  // merge_greedy_parallel: the same result, on a pool (keys below 2^32)
          NLOSLOC_ENSURE(!with_pairs, "with_pairs: not available with threads > 1 (use threads=1)");
          ThreadPool pool(threads);
          ParallelMergeWorkspace pws;
          int n = 0;
          {
            py::gil_scoped_release nogil;
            n = merge_greedy_parallel(keys.data(), logw.data(), static_cast<int>(keys.size()), close, pool,
                                      pws);
          }
          return py::make_tuple(logw, n);
        }
        MergeWorkspace ws;
        std::vector<int> pairs;
        const int n = merge_greedy(keys.data(), logw.data(), static_cast<int>(keys.size()), close, ws,
                                   [&](int a, int b, double) {
                                     if (!with_pairs) return;
                                     pairs.push_back(a);
                                     pairs.push_back(b);
                                   });
        if (!with_pairs) return py::make_tuple(logw, n);
        using Pairs = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;
        return py::make_tuple(logw, n, Pairs(Eigen::Map<const Pairs>(pairs.data(), n, 2)));
      },
      py::arg("keys"), py::arg("means"), py::arg("logw"), py::arg("d_min"), py::arg("with_pairs") = false,
      py::arg("threads") = 1,
      "Greedy merge of eqs. (29)-(30): keys (K,) situation keys, means (n, K), logw (K,). Returns (new logw, "
      "number absorbed), and with with_pairs=True also an (absorbed, 2) int array of (absorber, absorbed) "
      "pairs in merge order (each absorbed particle once; its weight moved is its input weight). threads > 1 "
      "runs merge_greedy_parallel (the joint PF's merge; keys below 2^32, no pairs): the same result on a "
      "pool of that many threads.");
  m.def(
      "enumerate_offspring",
      [](const bind::MatArg& A_in, const bind::UInt64Arg& limit_arg) {
        const MatX A = A_in.get("A");
        const std::uint64_t limit = limit_arg.get("limit");
        return enumerated(A, limit, [&](auto&& emit) { enumerate_offspring(A, limit, emit); });
      },
      py::arg("A"), py::arg("limit"),
      "The children of one particle as the RBPF expands them (Huerta eq. 23): every situation vector "
      "when N_z^B <= limit, in key order, else the `limit` with the largest sum_b A[b, s_b] (best first, "
      "enumerate_best). A (B, N_z): log factors per anchor and condition (finite or -inf). Returns (keys "
      "(K,) uint64 as encode_situation, sums (K,)).");
  m.def(
      "enumerate_best",
      [](const bind::MatArg& A_in, const bind::UInt64Arg& limit_arg) {
        const MatX A = A_in.get("A");
        const std::uint64_t limit = limit_arg.get("limit");
        return enumerated(A, limit, [&](auto&& emit) { enumerate_best(A, limit, emit); });
      },
      py::arg("A"), py::arg("limit"),
      "The `limit` situation vectors with the largest sum_b A[b, s_b], in decreasing order, ties by the "
      "smaller rank vector (exact best-first search: the RBPF's bounded enumeration). Returns (keys, "
      "sums) as enumerate_offspring.");
  m.def(
      "select_top",
      [](const bind::VecArg& logw_in, const bind::StrictArg<int>& M_in) {
        const VecX logw = logw_in.get("logw");
        const int M = M_in.get("M");
        NLOSLOC_ENSURE(M >= 1, "M: expected an integer >= 1, got " + std::to_string(M));
        check_log_weights(logw);
        std::vector<int> out;
        select_top(logw.data(), static_cast<int>(logw.size()), M, out);
        return out;
      },
      py::arg("logw"), py::arg("M"),
      "Indices of the (at most) M entries of logw with the largest finite log weights, heaviest first, "
      "ties by index (the prune step of Huerta Sec. V-A.3; -inf entries are never kept).");
  m.def(
      "systematic_resample",
      [](const bind::VecArg& w_in, const bind::StrictArg<int>& M_in, const bind::StrictArg<double>& u0_in) {
        const VecX w = w_in.get("w");
        const int M = M_in.get("M");
        const double u0 = u0_in.get("u0");
        NLOSLOC_ENSURE(w.size() >= 1 && M >= 1, "w, M: expected at least one weight and M >= 1");
        NLOSLOC_ENSURE(w.allFinite() && (w.array() >= 0.0).all() && std::abs(w.sum() - 1.0) < 1e-9,
                       "w: expected finite weights >= 0 summing to 1");
        NLOSLOC_ENSURE(u0 > 0.0 && u0 < 1.0, "u0: expected a value in (0, 1)");
        std::vector<int> out(static_cast<std::size_t>(M));
        systematic_resample(w, static_cast<int>(w.size()), M, u0, out.data());
        return out;
      },
      py::arg("w"), py::arg("M"), py::arg("u0"), "Ancestor indices of systematic resampling (normalised w).");
  m.def("situation_count", bind::strict_fn(&situation_count, "num_conditions", "num_anchors"),
        py::arg("num_conditions"), py::arg("num_anchors"), "N_z^B (0 when above 2^62).");
  m.def(
      "encode_situation",
      [](const py::object& sight, const bind::StrictArg<int>& nz_in) {
        const VecXi v = bind::to_sight(sight);
        const int nz = nz_in.get("num_conditions");
        NLOSLOC_ENSURE(nz >= 1, "num_conditions: expected an integer >= 1, got " + std::to_string(nz));
        NLOSLOC_ENSURE(situation_count(nz, static_cast<int>(v.size())) != 0,
                       "sight: " + std::to_string(v.size()) + " anchors with " + std::to_string(nz) +
                           " conditions have more than 2^62 situations (no key)");
        for (Eigen::Index b = 0; b < v.size(); ++b)
          NLOSLOC_ENSURE(v[b] >= 0 && v[b] < nz, "sight: expected conditions in [0, " + std::to_string(nz) +
                                                     "), got " + std::to_string(v[b]) + " at anchor " +
                                                     std::to_string(b));
        return encode_situation(v, nz);
      },
      py::arg("sight"), py::arg("num_conditions"),
      "Key of a situation vector (B,) of conditions in [0, N_z): its base-N_z digits, anchor 0 least "
      "significant (the keys of merge_greedy and of the RBPF's particles).");
  m.def(
      "decode_situation",
      [](const bind::UInt64Arg& key_arg, const bind::StrictArg<int>& nz_in,
         const bind::StrictArg<int>& B_in) {
        const std::uint64_t key = key_arg.get("key");
        const int nz = nz_in.get("num_conditions");
        const int B = B_in.get("num_anchors");
        const std::uint64_t count = situation_count(nz, B);  // checks nz >= 1, B >= 0
        NLOSLOC_ENSURE(count != 0, "num_anchors: " + std::to_string(B) + " anchors with " +
                                       std::to_string(nz) +
                                       " conditions have more than 2^62 situations (no key)");
        NLOSLOC_ENSURE(key < count, "key: expected a key below N_z^B = " + std::to_string(count) + ", got " +
                                        std::to_string(key));
        VecXi s(B);
        decode_situation(key, nz, s);
        return s;
      },
      py::arg("key"), py::arg("num_conditions"), py::arg("num_anchors"),
      "The situation vector (B,) of a key (inverse of encode_situation).");
  m.def("pf_simd_lanes", &pf_simd_lanes,
        "Doubles per SIMD packet in ParticleFilter's inner loops for this build of the module: 2 on x86-64 "
        "by default, 4 (AVX, AVX2) or 8 (AVX-512) when built with -Ccmake.define.NLOSLOC_NATIVE=ON on such a "
        "CPU.");
}
}  // namespace nlosloc::bind_rbpf_cpp

void bind_rbpf(py::module_& m) { nlosloc::bind_rbpf_cpp::define_module(m); }

namespace nlosloc::bind {

/// nlosloc.rbpf.Iukf as a sim::IukfEstimator, Rbpf as a sim::RbpfEstimator (a new filter per estimator,
/// with the given one's models and options) and ParticleFilter as a sim::PfEstimator (options.seed replaced
/// by a draw from the estimator's stream at every run, as for the registered PF). Null otherwise.
NativeMaker rbpf_maker(const py::handle& h, const std::string& name, const sim::Scenario& s) {
  if (py::isinstance<AnyIukf>(h))
    return h.cast<const AnyIukf&>().visit([&](const auto& f) -> NativeMaker {
      using M = std::decay_t<decltype(f.motion())>;
      check_fit(name, "Iukf", M::kDim, f.measurements().rows(), f.measurements().num_anchors(),
                f.motion().dt(), s);
      auto proto = std::make_shared<const Iukf<M>>(f);  // the filter without the Python accessors
      return [name, proto] { return std::make_unique<sim::IukfEstimator<M>>(name, *proto); };
    });
  if (py::isinstance<AnyRbpf>(h))
    return h.cast<const AnyRbpf&>().visit([&](const auto& f) -> NativeMaker {
      using M = std::decay_t<decltype(f.motion())>;
      check_fit(name, "Rbpf", M::kDim, f.measurements().rows(), f.num_anchors(), f.motion().dt(), s);
      // Rbpf owns a thread pool and is not copyable: each estimator builds one with the same set-up.
      auto proto = std::make_shared<const std::function<std::unique_ptr<rbpf::Rbpf<M>>()>>(
          [motion = f.motion(), meas = f.measurements(), sight = f.sight_process(), quality = f.quality(),
           start = f.belief(), options = f.options()] {
            return std::make_unique<rbpf::Rbpf<M>>(motion, meas, sight, quality, start, options);
          });
      return [name, proto] { return std::make_unique<sim::RbpfEstimator<M>>(name, (*proto)()); };
    });
  if (py::isinstance<AnyPf>(h))
    return h.cast<const AnyPf&>().visit([&](const auto& f) -> NativeMaker {
      using M = std::decay_t<decltype(f.motion())>;
      check_fit(name, "ParticleFilter", M::kDim, f.measurements().rows(), f.measurements().num_anchors(),
                f.motion().dt(), s);
      return [name, motion = f.motion(), meas = f.measurements(), sight = f.sight_process(),
              quality = f.quality(), options = f.options()] {
        return std::make_unique<sim::PfEstimator<M>>(name, motion, meas, sight, quality, options);
      };
    });
  return nullptr;
}

}  // namespace nlosloc::bind
