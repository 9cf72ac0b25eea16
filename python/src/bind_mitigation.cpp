/// \file bind_mitigation.cpp
/// nlosloc.mitigation: Ke & Wu 2011's box-QP adapter, Sec. 3 bias estimation, the proposed QP-bias EKF and
/// the bias-augmented ("iterated NLOS") EKF, with the C++ names. Solvers are chosen by name: "default"
/// (the C++ default of the class), "enumeration", "proxsuite", or "failing", a solver that never solves, to
/// exercise the fallbacks; or given as a Python object with solve(H, g, lower, upper) (PythonBoxQp).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "batch.hpp"
#include "bind.hpp"
#include "field_value.hpp"
#include "motion_arg.hpp"
#include "native_makers.hpp"
#include "nlosloc/mitigation/mitigation.hpp"
#include "nlosloc/sim/k1.hpp"
#include "params_field.hpp"
#include "py_object.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_mitigation_cpp {
using namespace nlosloc::mitigation;

namespace {

std::unique_ptr<BoxQp> solver_by_name(const std::string& name, int n, const BoxQpSettings& s) {
  if (name == "default") return make_box_qp(n, s);
  if (name == "enumeration") return std::make_unique<EnumerationBoxQp>(n, s);
  if (name == "proxsuite") return make_proxsuite_box_qp(n, s);
  if (name == "failing") return std::make_unique<FailingBoxQp>(n);
  throw std::invalid_argument("solver: expected 'default', 'enumeration', 'proxsuite' or 'failing', got '" +
                              name + "'");
}

/// A BoxQp whose solve() calls a Python object's solve(H, g, lower, upper), which returns the minimiser
/// (n,) or None when it found none (status kFailed): how Python users plug in their own QP solver, as C++
/// users derive from BoxQp. Every call takes the GIL (the trackers' run() and the Monte Carlo workers call
/// it without). A result of the wrong shape, or outside the box by more than 1e-6 (1 + |bound|), raises
/// ValueError naming the solver (the tracker is then unchanged); a non-finite one is a failure (kFailed),
/// as for the C++ solvers; one within that tolerance is projected onto the box, as ProxsuiteBoxQp's is.
/// clone() is copy.deepcopy of the object, so a tracker holding one can be copied (Monte Carlo workers); the
/// object is held as a SharedObject, released with the GIL on whatever thread the tracker dies.
class PythonBoxQp final : public BoxQp {
 public:
  /// With the GIL. TypeError when obj has no callable solve.
  PythonBoxQp(py::object obj, int n) : obj_(bind::share(std::move(obj))), n_(n) {
    py::object solve;
    if (py::hasattr(*obj_, "solve")) solve = obj_->attr("solve");
    if (!solve || PyCallable_Check(solve.ptr()) == 0)
      throw py::type_error(
          "solver: expected a solver name (str) or an object with a method solve(H, g, "
          "lower, upper), got " +
          bind::describe(*obj_));
    solve_ = bind::share(std::move(solve));
    work_.setZero(n, n);
    perm_.setZero(n);
    const py::object nm = py::getattr(*obj_, "name", py::none());
    name_ = py::isinstance<py::str>(nm)
                ? nm.cast<std::string>()
                : py::str(py::type::handle_of(*obj_).attr("__name__")).cast<std::string>();
    x_.setZero(n);
  }
  PythonBoxQp(const PythonBoxQp&) = delete;
  PythonBoxQp& operator=(const PythonBoxQp&) = delete;

  int size() const override { return n_; }
  std::string name() const override { return name_; }
  const VecX& x() const override { return x_; }
  /// The Python solver object (with the GIL).
  const py::object& object() const { return *obj_; }
  std::unique_ptr<BoxQp> clone() const override {
    py::gil_scoped_acquire gil;
    auto c = std::make_unique<PythonBoxQp>(py::module_::import("copy").attr("deepcopy")(*obj_), n_);
    c->x_ = x_;
    return c;
  }

  QpResult solve(const Eigen::Ref<const MatX>& H, const Eigen::Ref<const VecX>& g,
                 const Eigen::Ref<const VecX>& lower, const Eigen::Ref<const VecX>& upper) override {
    mitigation::detail::check_box_qp(n_, H, g, lower, upper, work_, perm_);  // H symmetric PSD, as built-ins
    QpResult res;
    res.objective = std::nan("");
    py::gil_scoped_acquire gil;
    const py::object r = (*solve_)(MatX(H), VecX(g), VecX(lower), VecX(upper));
    if (r.is_none()) {
      res.status = QpStatus::kFailed;
      x_.setZero();
      return res;
    }
    const auto a = bind::real_array(r, ("solver: solve() of '" + name_ + "'").c_str());
    if (!a || a.ndim() != 1 || a.size() != n_)
      throw py::value_error("solver: solve() of '" + name_ + "' returned " + bind::describe(r, a) +
                            "; expected the " + std::to_string(n_) + " values of the minimiser, or None");
    VecX x = Eigen::Map<const VecX>(a.data(), n_);
    if (!x.allFinite()) {
      res.status = QpStatus::kFailed;
      x_.setZero();
      return res;
    }
    for (int i = 0; i < n_; ++i) {
      const double tol_lo = 1e-6 * (1.0 + std::abs(lower[i])), tol_hi = 1e-6 * (1.0 + std::abs(upper[i]));
      if (x[i] < lower[i] - tol_lo || x[i] > upper[i] + tol_hi)
        throw py::value_error("solver: solve() of '" + name_ + "' returned x[" + std::to_string(i) +
                              "] = " + py::repr(py::float_(x[i])).cast<std::string>() + " outside [" +
                              py::repr(py::float_(lower[i])).cast<std::string>() + ", " +
                              py::repr(py::float_(upper[i])).cast<std::string>() + "]");
    }
    x_ = x.cwiseMax(lower).cwiseMin(upper);
    res.objective = 0.5 * x_.dot(H * x_) + g.dot(x_);
    res.status = QpStatus::kSolved;
    return res;
  }

 private:
  bind::SharedObject obj_, solve_;  // dropped with the GIL, on whatever thread the tracker dies
  int n_;
  std::string name_;
  VecX x_;
  MatX work_;   // scratch of the H check (n x n)
  VecXi perm_;  // scratch of the H check (n)
};

/// The trackers' `solver` argument: a name (solver_by_name; "default" gives null when `default_null`, the
/// tracker's own choice) or a Python solver object (PythonBoxQp).
std::unique_ptr<BoxQp> solver_arg(const py::object& solver, int n, const BoxQpSettings& s,
                                  bool default_null) {
  if (py::isinstance<py::str>(solver)) {
    const auto name = solver.cast<std::string>();
    if (name == "default" && default_null) return nullptr;
    return solver_by_name(name, n, s);
  }
  if (py::isinstance<BoxQp>(solver)) {  // a built-in solver object (make_box_qp): a copy of it, natively
    const auto& q = solver.cast<const BoxQp&>();
    if (q.size() != n)
      throw py::value_error("solver: expected a BoxQp of size " + std::to_string(n) +
                            " (one variable per anchor), got size " + std::to_string(q.size()));
    return clone_box_qp(q);
  }
  return std::make_unique<PythonBoxQp>(solver, n);
}

/// A copy of a tracker's solver for Python: copy.deepcopy of a Python solver object, else a BoxQp clone.
py::object solver_copy(const BoxQp& q) {
  if (const auto* p = dynamic_cast<const PythonBoxQp*>(&q))
    return py::module_::import("copy").attr("deepcopy")(p->object());
  return py::cast(clone_box_qp(q));
}

/// The settings a built-in solver was made with (enumeration, proxsuite); none for the others.
std::optional<BoxQpSettings> settings_of(const BoxQp& q) {
  if (const auto* e = dynamic_cast<const EnumerationBoxQp*>(&q)) return e->settings();
#ifdef NLOSLOC_HAVE_PROXSUITE
  if (const auto* p = dynamic_cast<const ProxsuiteBoxQp*>(&q)) return p->settings();
#endif
  return std::nullopt;
}

/// BoxQp pickling: the kind (a solver_by_name name), size and settings, and the enumeration's active set
/// (what its next solve starts from); x, the last solve's report, is not kept. Other solvers refuse.
py::tuple box_qp_state(const BoxQp& q) {
  if (const auto* e = dynamic_cast<const EnumerationBoxQp*>(&q))
    return py::make_tuple("enumeration", q.size(), e->settings(), e->active_set());
  if (dynamic_cast<const FailingBoxQp*>(&q) != nullptr)
    return py::make_tuple("failing", q.size(), BoxQpSettings(), py::none());
  if (const auto s = settings_of(q))  // the other built-in solver with settings
    return py::make_tuple("proxsuite", q.size(), *s, py::none());
  throw py::type_error("cannot pickle the BoxQp '" + q.name() + "': only the built-in solvers pickle");
}

std::unique_ptr<BoxQp> box_qp_from_state(const py::tuple& t) {
  if (t.size() != 4) throw py::value_error("BoxQp state: expected (kind, n, settings, active_set)");
  auto q = solver_by_name(t[0].cast<std::string>(), t[1].cast<int>(), t[2].cast<BoxQpSettings>());
  if (!t[3].is_none()) {
    auto* e = dynamic_cast<EnumerationBoxQp*>(q.get());
    if (e == nullptr) throw py::value_error("BoxQp state: an active set is only kept by 'enumeration'");
    e->set_active_set(t[3].cast<std::vector<int>>());
  }
  return q;
}

/// Row-major (T, M) batch of ranges.
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace

void define_module(pybind11::module_& m) {
  // ---- QP adapter ---------------------------------------------------------------------------------
  py::enum_<QpStatus>(m, "QpStatus", "Outcome of BoxQp.solve.")
      .value("Solved", QpStatus::kSolved)
      .value("MaxIterations", QpStatus::kMaxIterations)
      .value("PrimalInfeasible", QpStatus::kPrimalInfeasible)
      .value("DualInfeasible", QpStatus::kDualInfeasible)
      .value("Failed", QpStatus::kFailed);

  py::class_<BoxQpSettings>(m, "BoxQpSettings", "Accuracy settings of the box-QP solvers (DESIGN.md).")
      .def(py::init<>())
      .def_property("eps_abs", bind::field_get<&BoxQpSettings::eps_abs>(),
                    bind::field_set<&BoxQpSettings::eps_abs>("eps_abs"), "Absolute residual tolerance (> 0).")
      .def_property("check_duality_gap", bind::field_get<&BoxQpSettings::check_duality_gap>(),
                    bind::field_set<&BoxQpSettings::check_duality_gap>("check_duality_gap"),
                    "Also require a small gap.")
      .def_property("eps_duality_gap_abs", bind::field_get<&BoxQpSettings::eps_duality_gap_abs>(),
                    bind::field_set<&BoxQpSettings::eps_duality_gap_abs>("eps_duality_gap_abs"),
                    "Duality-gap tolerance.")
      .def_property("max_iter", bind::field_get<&BoxQpSettings::max_iter>(),
                    bind::field_set<&BoxQpSettings::max_iter>("max_iter"), "Iteration limit (>= 1).")
      .def_property("compute_preconditioner", bind::field_get<&BoxQpSettings::compute_preconditioner>(),
                    bind::field_set<&BoxQpSettings::compute_preconditioner>("compute_preconditioner"),
                    "Ruiz equilibration before each solve (off: problems are pre-scaled).");

  py::class_<QpResult>(m, "QpResult", "What one BoxQp.solve reports; the minimiser is BoxQp.x.")
      .def_readonly("status", &QpResult::status)
      .def_readonly("iterations", &QpResult::iterations)
      .def_readonly("objective", &QpResult::objective, "1/2 x^T H x + g^T x at x.")
      .def("ok", &QpResult::ok, "True when solved.");

  py::class_<BoxQp>(m, "BoxQp",
                    "Box-constrained convex QP: minimise 1/2 x^T H x + g^T x, lower <= x <= upper (Ke & Wu "
                    "eq. 14). Build one with make_box_qp(n).")
      .def_property_readonly("size", &BoxQp::size)
      .def_property_readonly("name", &BoxQp::name)
      .def(
          "solve",
          [](BoxQp& q, const bind::MatArg& H_in, const bind::VecArg& g_in, const bind::VecArg& lower_in,
             const bind::VecArg& upper_in) {
            const MatX H = H_in.get("H");
            const VecX g = g_in.get("g");
            const VecX lower = lower_in.get("lower");
            const VecX upper = upper_in.get("upper");
            py::gil_scoped_release nogil;
            return q.solve(H, g, lower, upper);
          },
          py::arg("H"), py::arg("g"), py::arg("lower"), py::arg("upper"),
          "Solves the QP. H (n, n) symmetric (to 1e-10 of its largest |entry|) positive semidefinite (to "
          "n 1e-12 of its largest diagonal entry), g, lower, upper (n,) finite, lower <= upper, else "
          "ValueError naming the argument; returns QpResult.")
      .def_property_readonly(
          "x", [](const BoxQp& q) { return VecX(q.x()); }, "Minimiser of the last solve (n,).")
      .def_property_readonly(
          "settings", [](const BoxQp& q) { return settings_of(q); },
          "The BoxQpSettings it was made with (a copy); None for 'failing'.")
      .def_property(
          "active_set",
          [](const BoxQp& q) -> py::object {
            if (const auto* e = dynamic_cast<const EnumerationBoxQp*>(&q)) return py::cast(e->active_set());
            return py::none();
          },
          [](BoxQp& q, const std::vector<int>& a) {
            auto* e = dynamic_cast<EnumerationBoxQp*>(&q);
            if (e == nullptr)
              throw py::value_error("active_set: only the 'enumeration' solver has one, this is '" +
                                    q.name() + "'");
            e->set_active_set(a);
          },
          "'enumeration' only (None otherwise): the active set its next solve tries first, per variable 0 "
          "free, 1 at its lower bound, 2 at its upper bound (on a singular H it picks the minimiser "
          "returned).")
      .def("clone", &clone_box_qp,
           "An independent solver that solves as this one would (BoxQp::clone); also copy.copy and "
           "copy.deepcopy.")
      .def("__copy__", &clone_box_qp)
      .def(
          "__deepcopy__", [](const BoxQp& q, const py::dict&) { return clone_box_qp(q); }, py::arg("memo"))
      .def(py::pickle(&box_qp_state, &box_qp_from_state));
  m.def(
      "make_box_qp",
      [](const bind::StrictArg<int>& n, const BoxQpSettings& s, const std::string& solver) {
        return solver_by_name(solver, n.get("n"), s);
      },
      py::arg("n"), py::arg_v("settings", BoxQpSettings(), "BoxQpSettings()"), py::arg("solver") = "default",
      "A BoxQp of n variables: solver 'default' (make_box_qp: proxsuite when built with it, else "
      "'enumeration'), 'enumeration' (exact KKT search over the active sets, n <= 8, no allocation in "
      "solve; on a singular H it returns a vertex of the optimal set), 'proxsuite' (dense QP) or "
      "'failing' (never solves).");
  m.attr("have_default_box_qp") = have_default_box_qp();
  m.attr("have_proxsuite_box_qp") = have_proxsuite_box_qp();

  // ---- Sec. 3 bias estimation ---------------------------------------------------------------------
  py::enum_<ReferenceKind>(m, "ReferenceKind", "How the reference point X0 was obtained (Sec. 3).")
      .value("FeasibleVertices", ReferenceKind::kFeasibleVertices)
      .value("Hint", ReferenceKind::kHint)
      .value("LeastSquares", ReferenceKind::kLeastSquares);
  py::enum_<BiasReference>(m, "BiasReference", "Residual and covariance of eq. (14) in QpBiasEkf.")
      .value("Prediction", BiasReference::kPrediction)
      .value("Snapshot", BiasReference::kSnapshot);
  m.attr("FLAG_REFERENCE_FALLBACK") = static_cast<unsigned>(kFlagReferenceFallback);
  m.attr("FLAG_BOUNDS_CLAMPED") = static_cast<unsigned>(kFlagBoundsClamped);
  m.attr("FLAG_QP_FAILED") = static_cast<unsigned>(kFlagQpFailed);
  m.attr("FLAG_DEGENERATE_GEOMETRY") = static_cast<unsigned>(kFlagDegenerateGeometry);
  m.attr("FLAG_MISSING_ROWS") = static_cast<unsigned>(kFlagMissingRows);
  m.attr("FLAG_UPDATE_REJECTED") = static_cast<unsigned>(kFlagUpdateRejected);

  py::class_<RangeNoise>(m, "RangeNoise", "Range noise std_i = sigma0 + relative * d_i (m).")
      .def(py::init([](const bind::StrictArg<double>& sigma0, const bind::StrictArg<double>& relative,
                       const bind::StrictArg<double>& min_std) {
             RangeNoise n{sigma0.get("sigma0"), relative.get("relative"), min_std.get("min_std")};
             n.validate("RangeNoise");
             return n;
           }),
           py::arg("sigma0") = 50.0, py::arg("relative") = 0.0, py::arg("min_std") = 1e-3)
      .def_property("sigma0", bind::field_get<&RangeNoise::sigma0>(),
                    bind::field_set<&RangeNoise::sigma0>("sigma0"))
      .def_property("relative", bind::field_get<&RangeNoise::relative>(),
                    bind::field_set<&RangeNoise::relative>("relative"))
      .def_property("min_std", bind::field_get<&RangeNoise::min_std>(),
                    bind::field_set<&RangeNoise::min_std>("min_std"))
      .def("std_at", &RangeNoise::std_at, py::arg("d"), "Noise std at distance d (m).")
      .def(
          "validate", [](const RangeNoise& n, const std::string& name) { n.validate(name.c_str()); },
          py::arg("name") = "noise",
          "Raises ValueError naming the field (as `name`.field) unless sigma0, relative >= 0 and "
          "min_std > 0, all finite.");

  py::class_<ReferencePoint>(m, "ReferencePoint", "Reference point X0 of Sec. 3.")
      .def_property_readonly("point", [](const ReferencePoint& r) { return VecX(r.point); })
      .def_readonly("kind", &ReferencePoint::kind)
      .def_readonly("vertices", &ReferencePoint::vertices);
  m.def(
      "reference_point",
      [](const bind::MatArg& anchors_in, const bind::VecArg& z_in,
         const std::optional<bind::VecArg>& hint_in) {
        const MatX anchors = anchors_in.get("anchors");
        const VecX z = z_in.get("z");
        const std::optional<VecX> hint = bind::optional_get(hint_in, "hint");
        nlosloc::detail::ensure_shape(anchors, -1, 2, "anchors");
        nlosloc::detail::ensure_shape(z, anchors.rows(), 1, "z");
        if (!hint) return reference_point(anchors, z);
        nlosloc::detail::ensure_shape(*hint, 2, 1, "hint");
        nlosloc::detail::ensure_finite(*hint, "hint");  // a NaN hint was silently ignored
        const Vec<2> h = *hint;
        return reference_point(anchors, z, &h);
      },
      py::arg("anchors"), py::arg("z"), py::arg("hint") = py::none(),
      "Centre of the feasible region of the range discs (Ke & Wu Sec. 3): mean of the region's vertices; "
      "without vertices, `hint` if given, else the least-squares range fit. anchors (M, 2) finite, M >= 2; "
      "z (M,) finite ranges >= 0; else ValueError naming the argument.");

  py::class_<BiasEstimate>(m, "BiasEstimate", "Result of BiasEstimator.estimate (Sec. 3).")
      .def_readonly("bias", &BiasEstimate::bias, "b^ of eq. (14) (M,), m.")
      .def_readonly("lower", &BiasEstimate::lower, "Lower bounds (eq. 14).")
      .def_readonly("upper", &BiasEstimate::upper, "Upper bounds (eq. 15, after the documented clamp).")
      .def_readonly("reference", &BiasEstimate::reference)
      .def_property_readonly(
          "x_tilde", [](const BiasEstimate& e) { return VecX(e.x_tilde); }, "Eq. (11).")
      .def_readonly("qp", &BiasEstimate::qp)
      .def_readonly("flags", &BiasEstimate::flags, "FLAG_* bits of the fallbacks taken.");

  py::class_<BiasEstimator>(m, "BiasEstimator", "Ke & Wu Sec. 3 NLOS bias estimation for fixed anchors.")
      .def(py::init([](const bind::MatArg& anchors_in, const py::object& solver, const BoxQpSettings& s) {
             const MatX anchors = anchors_in.get("anchors");
             nlosloc::detail::ensure_shape(anchors, -1, 2, "anchors");
             return std::make_unique<BiasEstimator>(
                 anchors, solver_arg(solver, static_cast<int>(anchors.rows()), s, false));
           }),
           py::arg("anchors"), py::arg("solver") = "default",
           py::arg_v("settings", BoxQpSettings(), "BoxQpSettings()"),
           "anchors (M, 2), M >= 3. solver: a name (as make_box_qp), a BoxQp of size M (a copy is used) or "
           "an object with solve(H, g, lower, upper) returning the minimiser (M,) or None (see QpBiasEkf).")
      .def(
          "estimate",
          [](BiasEstimator& e, const bind::VecArg& z_in, const bind::VecArg& variances_in,
             const std::optional<bind::VecArg>& hint_in) {
            const VecX z = z_in.get("z");
            const VecX variances = variances_in.get("variances");
            const std::optional<VecX> hint = bind::optional_get(hint_in, "hint");
            if (!hint) return e.estimate(z, variances);
            nlosloc::detail::ensure_shape(*hint, 2, 1, "hint");
            const Vec<2> h = *hint;
            return e.estimate(z, variances, &h);
          },
          py::arg("z"), py::arg("variances"), py::arg("hint") = py::none(),
          "Biases of ranges z (M,) with noise variances (M,) (eqs. 9-15); returns a BiasEstimate copy.")
      .def(
          "estimate_from_innovation",
          [](BiasEstimator& e, const bind::VecArg& z, const bind::VecArg& innovation, const bind::MatArg& D) {
            return e.estimate_from_innovation(z.get("z"), innovation.get("innovation"), D.get("D"));
          },
          py::arg("z"), py::arg("innovation"), py::arg("D"),
          "Eqs. (12)-(15) referenced to a tracker's prediction: r = innovation (M,) (eq. 26), L = I, "
          "Sigma_v = D (M, M) (eq. 27: F P F^T + R), bounds from the ranges z (M,); returns a BiasEstimate "
          "copy. D must be finite, symmetric and positive definite, else ValueError naming D (the "
          "estimator unchanged).")
      .def_property(
          "sparsity", &BiasEstimator::sparsity,
          [](BiasEstimator& e, const bind::StrictArg<double>& v) {
            e.set_sparsity(v.get("BiasEstimator.sparsity"));
          },
          "L1 tie-break weight added to eq. (14) (0 = plain eq. 14).")
      .def_property(
          "soft_threshold", &BiasEstimator::soft_threshold,
          [](BiasEstimator& e, const bind::StrictArg<double>& v) {
            e.set_soft_threshold(v.get("BiasEstimator.soft_threshold"));
          },
          "lambda of the soft threshold of estimate_from_innovation (0 = eq. 14 as written): with "
          "diagonal D, b_i = clip(r_i - lambda sqrt(D_ii), 0, b_i^U).")
      .def_property_readonly(
          "solver_name", [](const BiasEstimator& e) { return e.solver().name(); },
          "Name of the eq. (14) solver in use.")
      .def_property_readonly(
          "solver", [](const BiasEstimator& e) { return solver_copy(e.solver()); },
          "A copy of the eq. (14) solver: a BoxQp, or copy.deepcopy of your own solver object.")
      .def_property_readonly("last", &BiasEstimator::last, py::return_value_policy::copy,
                             "The last estimate (a BiasEstimate copy).")
      .def_property_readonly("size", &BiasEstimator::size)
      .def_property_readonly("anchors", &BiasEstimator::anchors)
      .def_property_readonly("H0", &BiasEstimator::H0, "Eq. (10), (M, 2).")
      .def_property_readonly("U", &BiasEstimator::U, "Eq. (11), (2, M).")
      .def_property_readonly("L", &BiasEstimator::L, "Eq. (12), (M, M).")
      .def_property_readonly("y", &BiasEstimator::y, py::return_value_policy::copy,
                             "Eq. (9) linearised measurement.")
      .def_property_readonly("r", &BiasEstimator::r, py::return_value_policy::copy, "Eq. (12) bias metric.")
      .def_property_readonly("sigma_v", &BiasEstimator::sigma_v, py::return_value_policy::copy,
                             "Eq. (13), L R L^T.")
      .def_property_readonly("sigma_v_ginv", &BiasEstimator::sigma_v_ginv, py::return_value_policy::copy,
                             "R^-1 L.")
      .def_property_readonly("qp_hessian", &BiasEstimator::qp_hessian, py::return_value_policy::copy)
      .def_property_readonly("qp_gradient", &BiasEstimator::qp_gradient, py::return_value_policy::copy);

  // ---- trackers -------------------------------------------------------------------------------------
  py::class_<QpBiasEkfOptions>(m, "QpBiasEkfOptions", "Options of QpBiasEkf.")
      .def(py::init<>())
      .def_property("gamma", bind::field_get<&QpBiasEkfOptions::gamma>(),
                    bind::field_set<&QpBiasEkfOptions::gamma>("gamma"), "Scaling factor of eq. (32), >= 1.")
      .def_property("noise", bind::field_get<&QpBiasEkfOptions::noise>(),
                    bind::field_set<&QpBiasEkfOptions::noise>("noise"), "RangeNoise of R(k).")
      .def_property("mitigate", bind::field_get<&QpBiasEkfOptions::mitigate>(),
                    bind::field_set<&QpBiasEkfOptions::mitigate>("mitigate"),
                    "False: plain EKF (eqs. 20-24).")
      .def_property("always_estimate", bind::field_get<&QpBiasEkfOptions::always_estimate>(),
                    bind::field_set<&QpBiasEkfOptions::always_estimate>("always_estimate"),
                    "Run the QP every step.")
      .def_property("sparsity", bind::field_get<&QpBiasEkfOptions::sparsity>(),
                    bind::field_set<&QpBiasEkfOptions::sparsity>("sparsity"),
                    "L1 tie-break of eq. (14) (SNAPSHOT only).")
      .def_property(
          "reference", bind::field_get<&QpBiasEkfOptions::reference>(),
          bind::field_set<&QpBiasEkfOptions::reference>("reference"),
          "BiasReference.Prediction (default: r = innovation, Sigma_v = eq. 27) or Snapshot (Sec. 3).")
      .def_property("drop_free_rows", bind::field_get<&QpBiasEkfOptions::drop_free_rows>(),
                    bind::field_set<&QpBiasEkfOptions::drop_free_rows>("drop_free_rows"),
                    "Leave rows whose b^_i is strictly inside its box out of the update (default True).")
      .def_property("soft_threshold", bind::field_get<&QpBiasEkfOptions::soft_threshold>(),
                    bind::field_set<&QpBiasEkfOptions::soft_threshold>("soft_threshold"),
                    "PREDICTION only: lambda of an L1 term on eq. (14) keeping rows within about lambda "
                    "standard deviations as LOS (0 = eq. 14 as written; not in the paper).")
      .def("validate", &QpBiasEkfOptions::validate,
           "Raises ValueError naming the field (options.gamma, options.noise.*, options.sparsity, "
           "options.reference, options.soft_threshold) that QpBiasEkf would refuse, with the message "
           "QpBiasEkf gives; the fields are not checked when set.");

  py::class_<MitigationStep>(m, "MitigationStep", "What one QpBiasEkf update reports.")
      .def_readonly("filter", &MitigationStep::filter, "StepResult (log-likelihood, rows used, status).")
      .def_readonly("nlos", &MitigationStep::nlos, "H1 of eq. (32).")
      .def_readonly("bias_estimated", &MitigationStep::bias_estimated)
      .def_readonly("innovation_sq", &MitigationStep::innovation_sq, "alpha^T alpha (eq. 31).")
      .def_readonly("threshold", &MitigationStep::threshold, "gamma Tr[F P F^T + R] (eq. 32).")
      .def_readonly("rows_dropped", &MitigationStep::rows_dropped,
                    "Rows left out because b^_i was strictly inside its box.")
      .def_readonly("flags", &MitigationStep::flags);

  py::class_<QpBiasEkf>(m, "QpBiasEkf",
                        "Ke & Wu 2011 proposed tracker: EKF with QP-estimated NLOS biases (eq. 25) and the "
                        "innovation test of eqs. (31)-(32). State [x, y, vx, vy].")
      .def(py::init([](const ConstantVelocity2& motion, const bind::MatArg& anchors_in,
                       const bind::VecArg& mean_in, const bind::MatArg& cov_in, const QpBiasEkfOptions& o,
                       const py::object& solver, const bind::StrictArg<double>& t0_in) {
             const MatX anchors = anchors_in.get("anchors");
             const VecX mean = mean_in.get("mean");
             const MatX cov = cov_in.get("cov");
             const double t0 = t0_in.get("t0");
             nlosloc::detail::ensure_shape(anchors, -1, 2, "anchors");
             // "default": QpBiasEkf's own choice (EnumerationBoxQp for the prediction reference, M <= 8)
             std::unique_ptr<BoxQp> qp =
                 solver_arg(solver, static_cast<int>(std::max<Eigen::Index>(anchors.rows(), 1)), {}, true);
             return std::make_unique<QpBiasEkf>(motion, anchors, bind::to_gaussian<4>(mean, cov), o,
                                                std::move(qp), t0);
           }),
           py::arg("motion"), py::arg("anchors"), py::arg("mean"), py::arg("cov"),
           py::arg_v("options", QpBiasEkfOptions(), "QpBiasEkfOptions()"), py::arg("solver") = "default",
           py::arg("t0") = 0.0,
           "motion: models.ConstantVelocity2 (eq. 16); anchors (M, 2); initial mean (4,), cov (4, 4). "
           "solver: 'default' (its own choice), 'enumeration', 'proxsuite', 'failing', a BoxQp of size M "
           "(make_box_qp; the tracker uses a copy), or your own: an "
           "object with solve(H, g, lower, upper) returning the minimiser (M,) of 1/2 x^T H x + g^T x on "
           "lower <= x <= upper, or None when it finds none (a failure: the tracker's fallback). It is "
           "called with the GIL; a result of the wrong shape or outside the box raises ValueError and "
           "leaves the tracker unchanged, as does an exception raised inside it. Copies of the tracker (the "
           "Monte Carlo workers') get copy.deepcopy of it.")
      .def_property_readonly(
          "solver_name", [](const QpBiasEkf& f) { return f.bias_estimator().solver().name(); },
          "Name of the eq. (14) solver in use (\"enumeration\", \"proxsuite-dense\", ...).")
      .def_property_readonly(
          "solver", [](const QpBiasEkf& f) { return solver_copy(f.bias_estimator().solver()); },
          "A copy of the eq. (14) solver: a BoxQp, or copy.deepcopy of your own solver object (what "
          "pickling the tracker stores).")
      .def("__copy__", [](const QpBiasEkf& f) { return QpBiasEkf(f); })
      .def(
          "__deepcopy__", [](const QpBiasEkf& f, const py::dict&) { return QpBiasEkf(f); }, py::arg("memo"),
          "An independent tracker in the same state, the last step's report included (its solver copied "
          "as QpBiasEkf.solver).")
      .def("predict", &QpBiasEkf::predict, "Eqs. (20)-(21).")
      .def("update", bind::vector_method<QpBiasEkf, &QpBiasEkf::update>("z"), py::arg("z"),
           "Update with ranges z (M,), NaN = missing.")
      .def("step", bind::vector_method<QpBiasEkf, &QpBiasEkf::step>("z"), py::arg("z"),
           "predict() then update(z).")
      .def(
          "run",
          [](QpBiasEkf& f, const bind::RowMatArg& Z_in, bool first_is_update) {
            const RowMat Z = Z_in.get("Z");
            nlosloc::detail::ensure_shape(Z, -1, f.num_anchors(), "Z");
            bind::check_steps(Z.rows(), [&](Eigen::Index k) {
              nlosloc::detail::check_measurement(Z.row(k).transpose(), f.num_anchors(), "Z");
            });
            RowMat X(Z.rows(), 4);
            {
              py::gil_scoped_release nogil;
              bind::run_steps(Z.rows(), [&](Eigen::Index k) {
                const VecX z = Z.row(k).transpose();
                if (k == 0 && first_is_update) {
                  f.update(z);
                } else {
                  f.step(z);
                }
                X.row(k) = f.mean().transpose();
              });
            }
            return X;
          },
          py::arg("Z"), py::arg("first_is_update") = true,
          "Runs over ranges Z (T, M); returns the means (T, 4). Row 0 is an update only by default. Every "
          "row is checked before the first step.")
      .def_property_readonly("mean", [](const QpBiasEkf& f) { return VecX(f.mean()); })
      .def_property_readonly("cov", [](const QpBiasEkf& f) { return MatX(f.cov()); })
      .def_property_readonly("time", &QpBiasEkf::time)
      .def_property_readonly(
          "bias", [](const QpBiasEkf& f) { return VecX(f.bias()); }, "b^ of the last update (M,) (a copy).")
      .def_property_readonly("motion", &QpBiasEkf::motion, py::return_value_policy::copy,
                             "The motion model (a copy).")
      .def(
          "belief", [](const QpBiasEkf& f) { return py::make_tuple(VecX(f.mean()), MatX(f.cov())); },
          "The belief as a tuple (mean (4,), cov (4, 4)).")
      .def_property_readonly("nlos_detected", &QpBiasEkf::nlos_detected)
      .def_property_readonly("last_step", &QpBiasEkf::last_step, py::return_value_policy::copy)
      .def_property_readonly(
          "bias_estimator", &QpBiasEkf::bias_estimator, py::return_value_policy::copy,
          "A copy of its Sec. 3 estimator: the last QP's bounds, reference point, status and intermediates "
          "(BiasEstimator.last, .qp_hessian, ...).")
      .def_property_readonly("num_anchors", &QpBiasEkf::num_anchors)
      .def_property_readonly("anchors", &QpBiasEkf::anchors)
      .def_property_readonly("options", &QpBiasEkf::options, py::return_value_policy::copy)
      .def(
          "set_belief",
          [](QpBiasEkf& f, const bind::VecArg& mean_in, const bind::MatArg& cov_in,
             const std::optional<bind::StrictArg<double>>& t_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const std::optional<double> t = bind::optional_get(t_in, "t");
            f.set_belief(bind::to_gaussian<4>(mean, cov), t.value_or(f.time()));
          },
          py::arg("mean"), py::arg("cov"), py::arg("t") = py::none(),
          "Replaces the belief and, when t is given, the time; clears the last bias and decision.");

  py::class_<BiasAugmentedEkfOptions>(m, "BiasAugmentedEkfOptions", "Options of BiasAugmentedEkf.")
      .def(py::init<>())
      .def_property("noise", bind::field_get<&BiasAugmentedEkfOptions::noise>(),
                    bind::field_set<&BiasAugmentedEkfOptions::noise>("noise"))
      .def_property("bias_prior_mean", bind::field_get<&BiasAugmentedEkfOptions::bias_prior_mean>(),
                    bind::field_set<&BiasAugmentedEkfOptions::bias_prior_mean>("bias_prior_mean"))
      .def_property("bias_prior_std", bind::field_get<&BiasAugmentedEkfOptions::bias_prior_std>(),
                    bind::field_set<&BiasAugmentedEkfOptions::bias_prior_std>("bias_prior_std"))
      .def_property("bias_walk_std", bind::field_get<&BiasAugmentedEkfOptions::bias_walk_std>(),
                    bind::field_set<&BiasAugmentedEkfOptions::bias_walk_std>("bias_walk_std"))
      .def_property("iterations", bind::field_get<&BiasAugmentedEkfOptions::iterations>(),
                    bind::field_set<&BiasAugmentedEkfOptions::iterations>("iterations"))
      .def_property("nonnegative", bind::field_get<&BiasAugmentedEkfOptions::nonnegative>(),
                    bind::field_set<&BiasAugmentedEkfOptions::nonnegative>("nonnegative"))
      .def("validate", &BiasAugmentedEkfOptions::validate,
           "Raises ValueError naming the field that BiasAugmentedEkf would refuse; the fields are not "
           "checked when set.");

  py::class_<BiasAugmentedEkf>(m, "BiasAugmentedEkf",
                               "Iterated NLOS EKF (Najar & Vidal 2003, Ke & Wu Sec. 1): state [x, y, vx, vy, "
                               "b_1..b_M], iterated EKF update.")
      .def(py::init([](const ConstantVelocity2& motion, const bind::MatArg& anchors_in,
                       const bind::VecArg& mean_in, const bind::MatArg& cov_in,
                       const BiasAugmentedEkfOptions& o, const bind::StrictArg<double>& t0_in) {
             const MatX anchors = anchors_in.get("anchors");
             const VecX mean = mean_in.get("mean");
             const MatX cov = cov_in.get("cov");
             const double t0 = t0_in.get("t0");
             return BiasAugmentedEkf(motion, anchors, bind::to_gaussian<4>(mean, cov), o, t0);
           }),
           py::arg("motion"), py::arg("anchors"), py::arg("mean"), py::arg("cov"),
           py::arg_v("options", BiasAugmentedEkfOptions(), "BiasAugmentedEkfOptions()"), py::arg("t0") = 0.0)
      .def("predict", &BiasAugmentedEkf::predict)
      .def("update", bind::vector_method<BiasAugmentedEkf, &BiasAugmentedEkf::update>("z"), py::arg("z"))
      .def("step", bind::vector_method<BiasAugmentedEkf, &BiasAugmentedEkf::step>("z"), py::arg("z"))
      .def_property_readonly(
          "mean", [](const BiasAugmentedEkf& f) { return VecX(f.mean()); },
          "[x, y, vx, vy, b_1..b_M] (a copy).")
      .def_property_readonly(
          "cov", [](const BiasAugmentedEkf& f) { return MatX(f.cov()); },
          "Covariance (4 + M, 4 + M) (a copy).")
      .def_property_readonly("kinematic_mean",
                             [](const BiasAugmentedEkf& f) { return VecX(f.kinematic_mean()); })
      .def_property_readonly("bias", &BiasAugmentedEkf::bias)
      .def_property_readonly("time", &BiasAugmentedEkf::time)
      .def_property_readonly("state_dim", &BiasAugmentedEkf::state_dim)
      .def_property_readonly("num_anchors", &BiasAugmentedEkf::num_anchors)
      .def_property_readonly(
          "anchors", [](const BiasAugmentedEkf& f) { return MatX(f.anchors()); }, "(M, 2).")
      .def_property_readonly("options", &BiasAugmentedEkf::options, py::return_value_policy::copy,
                             "The settings (a copy).")
      .def_property_readonly("motion", &BiasAugmentedEkf::motion, py::return_value_policy::copy,
                             "The motion model (a copy).")
      .def(
          "set_belief",
          [](BiasAugmentedEkf& f, const bind::VecArg& mean_in, const bind::MatArg& cov_in,
             const std::optional<bind::StrictArg<double>>& t_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const std::optional<double> t = bind::optional_get(t_in, "t");
            f.set_belief(bind::to_gaussian<4>(mean, cov), t.value_or(f.time()));
          },
          py::arg("mean"), py::arg("cov"), py::arg("t") = py::none(),
          "Sets the kinematic belief and, when t is given, the time; resets the biases to the prior.")
      .def(
          "set_augmented_belief",
          [](BiasAugmentedEkf& f, const bind::VecArg& mean_in, const bind::MatArg& cov_in,
             const std::optional<bind::StrictArg<double>>& t_in) {
            const VecX mean = mean_in.get("mean");
            const MatX cov = cov_in.get("cov");
            const std::optional<double> t = bind::optional_get(t_in, "t");
            nlosloc::detail::ensure_shape(mean, f.state_dim(), 1, "mean");
            nlosloc::detail::ensure_shape(cov, f.state_dim(), f.state_dim(), "cov");
            f.set_augmented_belief(Gaussian<Eigen::Dynamic>(mean, cov), t.value_or(f.time()));
          },
          py::arg("mean"), py::arg("cov"), py::arg("t") = py::none(),
          "Replaces the whole belief, biases included: mean (4 + M,) [x, y, vx, vy, b_1..b_M] and cov "
          "(4 + M, 4 + M), symmetric positive definite, and the time when t is given. With mean, cov and "
          "time, the filter's whole state (what pickling stores).")
      .def("__copy__", [](const BiasAugmentedEkf& f) { return BiasAugmentedEkf(f); })
      .def(
          "__deepcopy__", [](const BiasAugmentedEkf& f, const py::dict&) { return BiasAugmentedEkf(f); },
          py::arg("memo"), "An independent filter in the same state.");
}
}  // namespace nlosloc::bind_mitigation_cpp

void bind_mitigation(py::module_& m) { nlosloc::bind_mitigation_cpp::define_module(m); }

namespace nlosloc::bind {

/// The Ke & Wu trackers of nlosloc.mitigation (QpBiasEkf, BiasAugmentedEkf: state [x, y, vx, vy], one
/// range row per anchor) as their sim estimators, over a copy. Null otherwise.
NativeMaker mitigation_maker(const py::handle& h, const std::string& name, const sim::Scenario& s) {
  auto check = [&](const char* what, int anchors, double dt) {
    check_fit(name, what, 4, anchors, anchors, dt, s);
    const StateLayout& L = s.measurements().layout();
    if (L.position != 0 || L.space_dim != 2 || L.velocity != 2)
      throw py::value_error(who(name, what) + "tracks [x, y, vx, vy]; scenario " + s.name() +
                            " has another state layout");
  };
  if (py::isinstance<mitigation::QpBiasEkf>(h)) {
    // copied here, with the GIL: a solver that cannot be cloned is refused now, not on a worker
    auto proto = std::make_shared<const mitigation::QpBiasEkf>(h.cast<const mitigation::QpBiasEkf&>());
    check("QpBiasEkf", proto->num_anchors(), proto->motion().dt());
    return [name, proto] { return std::make_unique<sim::QpBiasEkfEstimator>(name, *proto); };
  }
  if (py::isinstance<mitigation::BiasAugmentedEkf>(h)) {
    auto proto =
        std::make_shared<const mitigation::BiasAugmentedEkf>(h.cast<const mitigation::BiasAugmentedEkf&>());
    check("BiasAugmentedEkf", proto->num_anchors(), proto->motion().dt());
    return [name, proto] { return std::make_unique<sim::BiasAugmentedEkfEstimator>(name, *proto); };
  }
  return nullptr;
}

}  // namespace nlosloc::bind
