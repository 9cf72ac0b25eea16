/// \file bind_core.cpp
/// nlosloc.core: Rng, sigma-point schemes, Cholesky fallback, log-sum-exp, angle wrapping, errors.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "bind.hpp"
#include "field_value.hpp"
#include "int_arg.hpp"
#include "nlosloc/core/cholesky.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/core/sigma_points.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_core_cpp {

/// A generator's whole state (Rng / BatchRng::save_state) as a list of 64-bit words.
template <class G>
std::vector<std::uint64_t> state_words(const G& g) {
  std::vector<std::uint64_t> w(G::kStateWords);
  g.save_state(w.data());
  return w;
}

/// Sets g from words of state_words(); ValueError naming `words` (g unchanged) for a wrong count or words no
/// generator has.
template <class G>
void set_state_words(G& g, const std::vector<std::uint64_t>& words) {
  NLOSLOC_ENSURE(words.size() == static_cast<std::size_t>(G::kStateWords),
                 "words: expected " + std::to_string(G::kStateWords) + " 64-bit words (save_state()), got " +
                     std::to_string(words.size()));
  NLOSLOC_ENSURE(g.restore_state(words.data()),
                 "words: no generator state (an all-zero state, or a flag or buffer position out of range)");
}

/// save_state / restore_state and pickling (as its state words) of a generator class.
template <class G, class C>
void state_methods(C& c) {
  c.def("save_state", &state_words<G>,
        "The whole state as a list of 64-bit words: restore_state() of it continues the same sequence.")
      .def("restore_state", &set_state_words<G>, py::arg("words"),
           "Sets the state from save_state() words (checked first: ValueError, nothing changed).")
      .def(py::pickle([](const G& g) { return py::make_tuple(state_words(g)); },
                      [](const py::tuple& t) {
                        G g;
                        set_state_words(g, t[0].cast<std::vector<std::uint64_t>>());
                        return g;
                      }));
}

void define_module(py::module_& m) {
  // register_exception also installs the translator: a bare py::exception<> only creates the type, and
  // the C++ NumericalError then reached Python as a plain RuntimeError.
  auto& numerical_error = py::register_exception<NumericalError>(m, "NumericalError", PyExc_RuntimeError);
  numerical_error.doc() =
      "Raised when a step cannot be completed numerically (a covariance that is not positive definite "
      "even with the Cholesky fallback). The filter keeps the belief it had before the call.";

  py::class_<Rng> rng(m, "Rng",
                      "Seeded xoshiro256++ generator; every random draw of nlosloc goes through one.");
  rng.def(py::init([](const bind::UInt64Arg& seed, const bind::UInt64Arg& stream) {
            return Rng(seed.get("seed"), stream.get("stream"));
          }),
          py::arg("seed") = 0, py::arg("stream") = 0,
          "Generator for `seed`; `stream` selects an independent sequence (e.g. a Monte Carlo run).")
      .def("uniform", &Rng::uniform, "Uniform draw in the open interval (0, 1).")
      .def("normal", py::overload_cast<>(&Rng::normal), "Standard normal draw.")
      .def(
          "normal",
          [](Rng& r, const bind::StrictArg<double>& mu_in, const bind::StrictArg<double>& sigma_in) {
            const double mu = mu_in.get("mu");
            const double sigma = sigma_in.get("sigma");
            if (!std::isfinite(mu)) throw std::invalid_argument("mu: expected a finite mean");
            if (!(sigma >= 0.0 && std::isfinite(sigma)))
              throw std::invalid_argument("sigma: expected a finite standard deviation >= 0, got " +
                                          std::to_string(sigma));
            return r.normal(mu, sigma);
          },
          py::arg("mu"), py::arg("sigma"), "Normal draw with mean mu and standard deviation sigma.")
      .def(
          "reseed",
          [](Rng& r, const bind::UInt64Arg& seed, const bind::UInt64Arg& stream) {
            r.reseed(seed.get("seed"), stream.get("stream"));
          },
          py::arg("seed"), py::arg("stream") = 0,
          "Restarts the generator as Rng(seed, stream) would (in place, e.g. the rng a Monte Carlo estimator "
          "is given).")
      .def(
          "normals",
          [](Rng& r, const bind::StrictArg<py::ssize_t>& n_in) {
            const py::ssize_t n = n_in.get("n");
            if (n < 0) throw std::invalid_argument("n: expected >= 0");
            py::array_t<double> out(n);
            auto v = out.mutable_unchecked<1>();
            for (py::ssize_t i = 0; i < n; ++i) v(i) = r.normal();
            return out;
          },
          py::arg("n"), "Array of `n` standard normal draws, shape (n,).")
      .def(
          "below",
          [](Rng& r, const bind::StrictArg<std::uint64_t>& n_in) {
            const std::uint64_t n = n_in.get("n");
            NLOSLOC_ENSURE(n >= 1, "n: expected an integer >= 1, got 0");  // [0, 0) is empty
            return r.below(n);
          },
          py::arg("n"), "Uniform integer in [0, n), n >= 1.")
      .def("jump", &Rng::jump,
           "Advances the generator by 2^128 draws (xoshiro256 jump): non-overlapping subsequences.")
      .def("state", &Rng::state, "The four 64-bit words of the xoshiro256 state.")
      .def(
          "__call__", [](Rng& r) { return r(); }, "Next raw 64-bit output.");
  state_methods<Rng>(rng);
  rng.attr("STATE_WORDS") = Rng::kStateWords;

  py::class_<BatchRng> batch(
      m, "BatchRng",
      "Bulk generator of the particle filter: 4 xoshiro256++ lanes in lockstep, lane l "
      "being the parent Rng jumped l + 1 times (the parent is not advanced).");
  batch
      .def(py::init<Rng>(), py::arg_v("parent", Rng(), "Rng()"),
           "Lanes derived from `parent` by jumps (default Rng(): seed 0, stream 0, as C++ BatchRng()).")
      .def(
          "bits",
          [](BatchRng& r, const bind::StrictArg<py::ssize_t>& n_in) {
            const py::ssize_t n_quads = n_in.get("n_quads");
            if (n_quads < 0 || n_quads > (py::ssize_t{1} << 28))
              throw std::invalid_argument("n_quads: expected 0 <= n_quads <= 2^28, got " +
                                          std::to_string(n_quads));
            py::array_t<std::uint64_t> out(4 * n_quads);
            r.fill_bits(out.mutable_data(), static_cast<int>(n_quads));
            return out;
          },
          py::arg("n_quads"),
          "4 * n_quads raw words, shape (4 n_quads,): word 4 j + l is lane l's j-th output.")
      .def(
          "uniforms",
          [](BatchRng& r, const bind::StrictArg<py::ssize_t>& n_in) {
            const py::ssize_t n = n_in.get("n");
            if (n < 0 || n % BatchRng::kLanes != 0 || n > (py::ssize_t{1} << 30))
              throw std::invalid_argument("n: expected a multiple of 4 in [0, 2^30], got " +
                                          std::to_string(n));
            py::array_t<double> out(n);
            r.fill_uniform(out.mutable_data(), static_cast<int>(n));
            return out;
          },
          py::arg("n"), "n uniforms in (0, 1) with 52 random bits each, n a multiple of 4; shape (n,).")
      .def(
          "normals",
          [](BatchRng& r, const bind::StrictArg<py::ssize_t>& n_in) {
            const py::ssize_t n = n_in.get("n");
            if (n < 0 || n > (py::ssize_t{1} << 30))
              throw std::invalid_argument("n: expected 0 <= n <= 2^30, got " + std::to_string(n));
            py::array_t<double> out(n);
            r.fill_normal(out.mutable_data(), static_cast<int>(n));
            return out;
          },
          py::arg("n"), "n standard normal variates (ziggurat, Marsaglia and Tsang 2000); shape (n,).")
      .def("uniform", &BatchRng::uniform, "One uniform in (0, 1) with 53 random bits.")
      .def(
          "__call__", [](BatchRng& r) { return r.next(); }, "Next raw 64-bit word.")
      .def(
          "use_avx2", [](BatchRng& r, const bind::StrictArg<bool>& on) { r.use_avx2(on.get("on")); },
          py::arg("on"),
          "Refill on 256-bit AVX2 registers from now on (on, and the CPU has AVX2; x86-64 GCC/Clang "
          "builds) or on SSE2 / scalar code (the default). The words are the same either way; not part "
          "of save_state().")
      .def_property_readonly("uses_avx2", &BatchRng::uses_avx2, "Whether refills run on AVX2 registers.");
  state_methods<BatchRng>(batch);
  batch.attr("STATE_WORDS") = BatchRng::kStateWords;
  batch.attr("LANES") = BatchRng::kLanes;
  batch.attr("BUFFER") = BatchRng::kBuffer;

  py::class_<SigmaWeights>(m, "SigmaWeights", "Weights of a 2n+1 sigma-point set.")
      .def_readonly("gamma", &SigmaWeights::gamma, "Spread: points are mean +- gamma * L[:, i].")
      .def_readonly("wm0", &SigmaWeights::wm0, "Mean weight of the centre point.")
      .def_readonly("wc0", &SigmaWeights::wc0, "Covariance weight of the centre point.")
      .def_readonly("wi", &SigmaWeights::wi, "Weight of each of the 2n outer points.");

  py::class_<SigmaScheme> sch(m, "SigmaScheme", "Sigma-point rule of the unscented transform.");
  py::enum_<SigmaScheme::Kind>(sch, "Kind")
      .value("Scaled", SigmaScheme::Kind::kScaled)
      .value("Julier", SigmaScheme::Kind::kJulier)
      .value("Cubature", SigmaScheme::Kind::kCubature)
      .value("Huerta", SigmaScheme::Kind::kHuerta);
  sch.def(py::init([](const bind::StrictArg<SigmaScheme::Kind>& kind, const bind::StrictArg<double>& alpha,
                      const bind::StrictArg<double>& beta, const bind::StrictArg<double>& kappa) {
            return SigmaScheme{kind.get("kind"), alpha.get("alpha"), beta.get("beta"), kappa.get("kappa")};
          }),
          py::arg_v("kind", SigmaScheme::Kind::kScaled, "SigmaScheme.Kind.Scaled"), py::arg("alpha") = 1.0,
          py::arg("beta") = 2.0, py::arg("kappa") = 0.0,
          "A scheme from its four fields, as the C++ aggregate (checked when weights() or validate() are "
          "called; the factories below give each kind's usual parameters).")
      .def_static("scaled", &SigmaScheme::scaled, py::arg("alpha") = 1e-3, py::arg("beta") = 2.0,
                  py::arg("kappa") = 0.0,
                  "Scaled UT of Wan and van der Merwe (FilterPy's MerweScaledSigmaPoints); alpha in (0, 1].")
      .def_static("julier", &SigmaScheme::julier, py::arg("kappa") = 0.0, "Julier and Uhlmann's UT.")
      .def_static("cubature", &SigmaScheme::cubature, "Spherical-radial cubature rule (2n points).")
      .def_static("huerta", &SigmaScheme::huerta, py::arg("alpha") = 1.0,
                  "Huerta et al. 2009 eqs. (49)-(52) (scaled rule with kappa = 0, beta = 2).")
      .def_readonly("kind", &SigmaScheme::kind)
      .def_readonly("alpha", &SigmaScheme::alpha)
      .def_readonly("beta", &SigmaScheme::beta)
      .def_readonly("kappa", &SigmaScheme::kappa)
      .def("validate", &SigmaScheme::validate, py::arg("n"),
           "Raises ValueError (naming the parameter) unless the scheme gives valid weights for dimension n.")
      .def("weights", &SigmaScheme::weights, py::arg("n"), "Weights for an n-dimensional variable.")
      .def("__eq__",
           [](const SigmaScheme& a, const py::object& other) -> py::object {
             // NotImplemented for another type, so `scheme == None` is False (it raised TypeError)
             if (!py::isinstance<SigmaScheme>(other))
               return py::reinterpret_borrow<py::object>(Py_NotImplemented);
             const auto& b = other.cast<const SigmaScheme&>();
             return py::bool_(a.kind == b.kind && a.alpha == b.alpha && a.beta == b.beta &&
                              a.kappa == b.kappa);
           })
      // Equal schemes hash alike (defining __eq__ alone leaves a pybind11 class unhashable).
      .def("__hash__", [](const SigmaScheme& s) {
        return py::hash(py::make_tuple(static_cast<int>(s.kind), s.alpha, s.beta, s.kappa));
      });

  m.def(
      "sigma_points",
      [](const bind::VecArg& mean_in, const bind::MatArg& cov_in, const SigmaScheme& scheme) {
        const VecX mean = mean_in.get("mean");
        const MatX cov = cov_in.get("cov");
        detail::ensure_shape(cov, mean.size(), mean.size(), "cov");
        detail::ensure_finite(mean, "mean");
        // robust_cholesky factors the symmetric part, so a non-symmetric cov would pass as another matrix
        if (detail::symmetric_scale(cov, 1e-9) == 0.0)
          throw std::invalid_argument(
              "cov: expected a finite symmetric matrix (to 1e-9 of its largest entry)");
        const SigmaWeights w = scheme.weights(static_cast<int>(mean.size()));
        MatX L(mean.size(), mean.size());
        if (robust_cholesky(cov, L) == CholeskyStatus::kFailed)
          throw std::invalid_argument("cov: expected a symmetric positive definite matrix");
        MatX X(mean.size(), 2 * mean.size() + 1);
        sigma_points(mean, L, w.gamma, X);
        return MatX(X.transpose());
      },
      py::arg("mean"), py::arg("cov"), py::arg("scheme"),
      "Sigma points of N(mean, cov) as rows, shape (2n+1, n), in the order of FilterPy's "
      "MerweScaledSigmaPoints: centre, +gamma columns of L, -gamma columns.");

  py::enum_<CholeskyStatus>(m, "CholeskyStatus", "Outcome of a factorisation (see robust_cholesky).")
      .value("Ok", CholeskyStatus::kOk)
      .value("Jittered", CholeskyStatus::kJittered)
      .value("Failed", CholeskyStatus::kFailed);

  m.def(
      "robust_cholesky",
      [](const bind::MatArg& A_in) {
        const MatX A = A_in.get("A");
        NLOSLOC_ENSURE(A.rows() == A.cols(), "A: expected a square matrix");
        MatX L = MatX::Zero(A.rows(), A.cols());
        double jitter = 0.0;
        const CholeskyStatus s = robust_cholesky(A, L, &jitter);
        return py::make_tuple(L, s, jitter);
      },
      py::arg("A"),
      "Lower Cholesky factor with the documented fallback: returns (L, status, jitter). A plain LLT of "
      "(A + A^T)/2 first; on failure retries with eps * mean(diag) added, eps = 1e-12, 1e-10, 1e-8; "
      "status Failed when all fail (L is then unusable).");
  m.def(
      "log_sum_exp",
      [](const bind::VecArg& v_in) {
        const VecX v = v_in.get("v");
        return log_sum_exp(v);
      },
      py::arg("v"), "log(sum(exp(v))) computed stably; -inf for empty input.");
  m.def("wrap_angle", py::vectorize(&wrap_angle), py::arg("a"), "Wraps angles (rad) to (-pi, pi].");
  m.def(
      "log_normalize",
      [](const bind::VecArg& v_in) {
        VecX v = v_in.get("v");
        const double z = log_normalize(v);
        return py::make_tuple(v, z);
      },
      py::arg("v"),
      "Log weights normalised so that sum(exp) = 1, and the normaliser log_sum_exp(v): a tuple (v - z, z) "
      "(v unchanged when z is not finite).");
  m.def(
      "gaussian_log_pdf_chol",
      [](const bind::MatArg& L_in, const bind::VecArg& x_in) {
        const MatX L = L_in.get("L");
        const VecX x = x_in.get("x");
        detail::ensure_shape(L, x.size(), x.size(), "L");
        if (!L.allFinite() || !(L.diagonal().array() > 0.0).all() ||
            !MatX(L.triangularView<Eigen::StrictlyUpper>()).isZero(0.0))
          throw std::invalid_argument(
              "L: expected a lower-triangular Cholesky factor with a positive diagonal (robust_cholesky)");
        return gaussian_log_pdf_chol(L, x);
      },
      py::arg("L"), py::arg("x"), "log N(x; 0, S) from the lower Cholesky factor L of S (m, m) and x (m,).");
  m.def(
      "is_spd",
      [](const bind::MatArg& A_in, double rel_tol) {
        const MatX A = A_in.get("A");
        return is_spd(A, rel_tol);
      },
      py::arg("A"), py::arg("rel_tol") = 1e-9,
      "True when A is square, finite, symmetric to rel_tol (relative to its largest entry) and positive "
      "definite: the check set_belief applies to a covariance.");
  m.def(
      "is_spsd",
      [](const bind::MatArg& A_in, double rel_tol) {
        const MatX A = A_in.get("A");
        return is_spsd(A, rel_tol);
      },
      py::arg("A"), py::arg("rel_tol") = 1e-9,
      "True when A is square, finite, symmetric to rel_tol (relative to its largest entry) and positive "
      "semi-definite (LDLT pivots >= -rel_tol max|A|): the check a particle set's covariance passes.");
  m.def(
      "are_log_weights",
      [](const bind::VecArg& v_in) {
        const VecX v = v_in.get("v");
        return are_log_weights(v);
      },
      py::arg("v"),
      "True when every entry is a valid log weight: finite or -inf (a ruled-out particle), never NaN or "
      "+inf.");
  m.attr("SPEED_OF_LIGHT") = kSpeedOfLight;
}
}  // namespace nlosloc::bind_core_cpp

void bind_core(py::module_& m) { nlosloc::bind_core_cpp::define_module(m); }
