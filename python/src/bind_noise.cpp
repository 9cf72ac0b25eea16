/// \file bind_noise.cpp
/// nlosloc.noise: the noise distributions of nlosloc/models/noise.hpp and the type-erased Distribution.
/// log_pdf, pdf, cdf, quantile and from_standard_normal are vectorised (float in -> float out, array in ->
/// array of the same shape out); sample(rng, size) draws through the library's Rng.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "bind.hpp"
#include "field_value.hpp"
#include "motion_arg.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/models/noise.hpp"

namespace py = pybind11;

// Helpers and using-directives stay in this file's namespace: the extension builds in unity batches.
namespace nlosloc::bind_noise_cpp {
using namespace nlosloc::noise;

namespace {

std::string repr_of(const Normal& d) {
  return "Normal(mean=" + float_repr(d.mean()) + ", std=" + float_repr(d.stddev()) + ")";
}
std::string repr_of(const Rayleigh& d) { return "Rayleigh(scale=" + float_repr(d.scale()) + ")"; }
std::string repr_of(const Exponential& d) { return "Exponential(mean=" + float_repr(d.mean()) + ")"; }
std::string repr_of(const Gev& d) {
  return "Gev(shape=" + float_repr(d.shape()) + ", loc=" + float_repr(d.loc()) +
         ", scale=" + float_repr(d.scale()) + ")";
}
std::string repr_of(const TruncatedNormal& d) {
  return "TruncatedNormal(mu=" + float_repr(d.mu()) + ", sigma=" + float_repr(d.sigma()) +
         ", lower=" + float_repr(d.lower()) + ", upper=" + float_repr(d.upper()) + ")";
}
std::string repr_of(const ShiftedNormal& d) {
  return "ShiftedNormal(shift=" + float_repr(d.shift()) + ", std=" + float_repr(d.stddev()) + ")";
}
std::string repr_of(const AsymmetricNormal& d) {
  return "AsymmetricNormal(mode=" + float_repr(d.mode()) + ", sigma_left=" + float_repr(d.sigma_left()) +
         ", sigma_right=" + float_repr(d.sigma_right()) + ")";
}
std::string repr_of(const Beta& d) {
  return "Beta(a=" + float_repr(d.a()) + ", b=" + float_repr(d.b()) + ")";
}
std::string repr_of(const Empirical& d) {
  return "Empirical(n=" + std::to_string(d.size()) + ", bandwidth=" + float_repr(d.bandwidth()) + ")";
}
std::string repr_of(const Distribution& d) {
  return "Distribution(" + std::visit([](const auto& x) { return repr_of(x); }, d.variant()) + ")";
}

/// `size` draws of d as an array of shape (size,), or one float when size is None.
template <class D>
py::object draw(const D& d, Rng& rng, std::optional<py::ssize_t> size) {
  if (!size) return py::float_(d.sample(rng));
  if (*size < 0)
    throw std::invalid_argument("sample: size: expected an integer >= 0, got " + std::to_string(*size));
  py::array_t<double> out(*size);
  auto v = out.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < *size; ++i) v(i) = d.sample(rng);
  return std::move(out);
}

/// The methods shared by every distribution class and by Distribution.
template <class D, class Cls>
void def_common(Cls& cls) {
  cls.def("log_pdf", py::vectorize([](const D* d, double x) { return d->log_pdf(x); }), py::arg("x"),
          R"doc(Log density.

Parameters
----------
x : float or numpy.ndarray
    Points, any shape, in the unit of the distribution.

Returns
-------
float or numpy.ndarray
    log p(x), same shape as `x`; -inf outside the support, NaN where `x` is NaN.
)doc")
      .def("pdf", py::vectorize([](const D* d, double x) { return d->pdf(x); }), py::arg("x"),
           R"doc(Density p(x).

Parameters
----------
x : float or numpy.ndarray
    Points, any shape.

Returns
-------
float or numpy.ndarray
    p(x), same shape as `x` (unit: 1/unit of x); 0 outside the support.
)doc")
      .def("cdf", py::vectorize([](const D* d, double x) { return d->cdf(x); }), py::arg("x"),
           R"doc(Cumulative distribution function P(X <= x).

Parameters
----------
x : float or numpy.ndarray
    Points, any shape.

Returns
-------
float or numpy.ndarray
    Probabilities in [0, 1], same shape as `x`.
)doc")
      .def("quantile", py::vectorize([](const D* d, double p) { return d->quantile(p); }), py::arg("p"),
           R"doc(Inverse cdf.

Parameters
----------
p : float or numpy.ndarray
    Probabilities in the open interval (0, 1), any shape.

Returns
-------
float or numpy.ndarray
    x with P(X <= x) = p, same shape as `p`.

Raises
------
ValueError
    If a probability is outside (0, 1).
)doc")
      .def("from_standard_normal",
           py::vectorize([](const D* d, double u) { return d->from_standard_normal(u); }), py::arg("u"),
           R"doc(Gaussian-quantile transform x = F^-1(Phi(u)) (Huerta 2009 Sec. V-A, Grisales eq. 29).

Computed tail-safely: for u > 0 the upper-tail probability Phi(-u) is inverted with the complementary
quantile, so large u stay distinct. For the normal classes it is exactly mean + std * u.

Parameters
----------
u : float or numpy.ndarray
    Standard normal values, any shape.

Returns
-------
float or numpy.ndarray
    Transformed values, same shape as `u`.
)doc")
      .def("mean", &D::mean, "Mean of the distribution (inf when it does not exist).")
      .def("variance", &D::variance, "Variance of the distribution (inf when it does not exist).")
      .def(
          "sample", [](const D& d, Rng& rng, std::optional<py::ssize_t> size) { return draw(d, rng, size); },
          py::arg("rng"), py::arg("size") = py::none(),
          R"doc(Random draws.

Parameters
----------
rng : nlosloc.core.Rng
    Generator; advanced by the draws.
size : int, optional
    Number of draws. None (default) returns one float.

Returns
-------
float or numpy.ndarray
    One draw, or an array of shape (size,).
)doc")
      .def(
          "name", [](const D& d) { return std::string(d.name()); }, "Class name, e.g. 'Rayleigh'.")
      .def("__repr__", [](const D& d) { return repr_of(d); });
}

}  // namespace

void define_module(py::module_& m) {
  // ---- Normal
  py::class_<Normal> normal(m, "Normal", R"doc(Normal distribution N(mean, std^2).

LOS noise of every paper (Huerta Table VIII, Ke & Wu Sec. 6); soft-NLOS delay of Grisales (0.35 ns, 0.07 ns).

Parameters
----------
mean : float
    Mean, finite (unit of x). Also returned by ``mean()``.
std : float
    Standard deviation > 0 (unit of x).
)doc");
  normal.def(bind::strict_init<Normal, double, double>("mean", "std"), py::arg("mean"), py::arg("std"))
      .def_property_readonly("std", &Normal::stddev, "Standard deviation.")
      .def(py::pickle([](const Normal& d) { return py::make_tuple(d.mean(), d.stddev()); },
                      [](const py::tuple& t) { return Normal(t[0].cast<double>(), t[1].cast<double>()); }));
  def_common<Normal>(normal);

  // ---- Rayleigh
  py::class_<Rayleigh> rayleigh(m, "Rayleigh", R"doc(Rayleigh distribution with scale s.

pdf x / s^2 exp(-x^2 / (2 s^2)) for x >= 0; mean s sqrt(pi/2), variance (4 - pi)/2 s^2. NLOS TOA error of
Huerta Table VIII (variance 2000 m^2) and Table X (5000 m^2): use ``Rayleigh.from_variance``.

Parameters
----------
scale : float
    Scale s > 0 (unit of x).
)doc");
  rayleigh.def(bind::strict_init<Rayleigh, double>("scale"), py::arg("scale"))
      .def_static("from_variance", &Rayleigh::from_variance, py::arg("variance"),
                  R"doc(Rayleigh with the given variance: scale = sqrt(2 variance / (4 - pi)).

Parameters
----------
variance : float
    Variance > 0 (unit of x squared).

Returns
-------
Rayleigh
)doc")
      .def_property_readonly("scale", &Rayleigh::scale, "Scale s.")
      .def(py::pickle([](const Rayleigh& d) { return py::make_tuple(d.scale()); },
                      [](const py::tuple& t) { return Rayleigh(t[0].cast<double>()); }));
  def_common<Rayleigh>(rayleigh);

  // ---- Exponential
  py::class_<Exponential> exponential(m, "Exponential", R"doc(Exponential distribution with mean m.

pdf exp(-x/m)/m for x >= 0, variance m^2. NLOS range error of Ke & Wu Sec. 6.4 (mean 0.08 d_i).

Parameters
----------
mean : float
    Mean m > 0 (unit of x); the rate is 1/m. Also returned by ``mean()``.
)doc");
  exponential.def(bind::strict_init<Exponential, double>("mean"), py::arg("mean"))
      .def(py::pickle([](const Exponential& d) { return py::make_tuple(d.mean()); },
                      [](const py::tuple& t) { return Exponential(t[0].cast<double>()); }));
  def_common<Exponential>(exponential);

  // ---- Gev
  py::class_<Gev> gev(m, "Gev",
                      R"doc(Generalized extreme value distribution GEV(shape k, loc mu, scale sigma).

cdf exp(-(1 + k (x - mu)/sigma)^(-1/k)) where 1 + k (x - mu)/sigma > 0; Gumbel at k = 0 (Coles 2001 eq. 3.2).
k > 0 is the heavy (Frechet) upper tail, as in Grisales Sec. 5 (hard NLOS: k = 0.4, mu = 8.5 ns,
sigma = 4.25 ns). scipy.stats.genextreme uses the opposite sign: ``genextreme(c=-k, loc=mu, scale=sigma)``.
The mean is inf for k >= 1, the variance inf for k >= 1/2.

Parameters
----------
shape : float
    Shape k, finite.
loc : float
    Location mu, finite (unit of x).
scale : float
    Scale sigma > 0 (unit of x).
)doc");
  gev.def(bind::strict_init<Gev, double, double, double>("shape", "loc", "scale"), py::arg("shape"),
          py::arg("loc"), py::arg("scale"))
      .def_property_readonly("shape", &Gev::shape, "Shape k (k > 0: heavy upper tail).")
      .def_property_readonly("loc", &Gev::loc, "Location mu.")
      .def_property_readonly("scale", &Gev::scale, "Scale sigma.")
      .def(py::pickle([](const Gev& d) { return py::make_tuple(d.shape(), d.loc(), d.scale()); },
                      [](const py::tuple& t) {
                        return Gev(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>());
                      }));
  def_common<Gev>(gev);

  // ---- TruncatedNormal
  py::class_<TruncatedNormal> truncated(m, "TruncatedNormal",
                                        R"doc(Normal N(mu, sigma^2) truncated to [lower, upper].

Bias prior of Giremus & Grolleau Sec. 5 (N(2000, 2000^2/9) on x > 0). Equals
``scipy.stats.truncnorm((lower - mu)/sigma, (upper - mu)/sigma, loc=mu, scale=sigma)``.

Parameters
----------
mu : float
    Mean of the parent normal, finite (unit of x).
sigma : float
    Standard deviation of the parent normal > 0 (unit of x).
lower : float
    Lower bound, may be -inf.
upper : float
    Upper bound > lower, may be inf.
)doc");
  truncated
      .def(
          bind::strict_init<TruncatedNormal, double, double, double, double>("mu", "sigma", "lower", "upper"),
          py::arg("mu"), py::arg("sigma"), py::arg("lower"), py::arg("upper"))
      .def_property_readonly("mu", &TruncatedNormal::mu, "Mean of the parent normal.")
      .def_property_readonly("sigma", &TruncatedNormal::sigma, "Standard deviation of the parent normal.")
      .def_property_readonly("lower", &TruncatedNormal::lower, "Lower bound.")
      .def_property_readonly("upper", &TruncatedNormal::upper, "Upper bound.")
      .def(py::pickle(
          [](const TruncatedNormal& d) { return py::make_tuple(d.mu(), d.sigma(), d.lower(), d.upper()); },
          [](const py::tuple& t) {
            return TruncatedNormal(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>(),
                                   t[3].cast<double>());
          }));
  def_common<TruncatedNormal>(truncated);

  // ---- ShiftedNormal
  py::class_<ShiftedNormal> shifted(m, "ShiftedNormal",
                                    R"doc(Normal N(shift, std^2) with a positive mean: an NLOS bias.

Ke & Wu Sec. 6.1: N(513 m, 436^2 m^2).

Parameters
----------
shift : float
    Mean (the bias) > 0 (unit of x).
std : float
    Standard deviation > 0 (unit of x).
)doc");
  shifted
      .def(bind::strict_init<ShiftedNormal, double, double>("shift", "std"), py::arg("shift"), py::arg("std"))
      .def_property_readonly("shift", &ShiftedNormal::shift, "Mean shift (bias).")
      .def_property_readonly("std", &ShiftedNormal::stddev, "Standard deviation.")
      .def(py::pickle(
          [](const ShiftedNormal& d) { return py::make_tuple(d.shift(), d.stddev()); },
          [](const py::tuple& t) { return ShiftedNormal(t[0].cast<double>(), t[1].cast<double>()); }));
  def_common<ShiftedNormal>(shifted);

  // ---- AsymmetricNormal
  py::class_<AsymmetricNormal> asym(m, "AsymmetricNormal",
                                    R"doc(Asymmetric (split, two-piece) normal of Cong & Zhuang 2005.

pdf 2 / (sqrt(2 pi) (sl + sr)) exp(-(x - mode)^2 / (2 s^2)) with s = sl left of the mode and s = sr right of it.
Mean mode + sqrt(2/pi) (sr - sl), variance (1 - 2/pi) (sr - sl)^2 + sl sr (Wallis 2014).

Parameters
----------
mode : float
    Mode, finite (unit of x).
sigma_left : float
    Standard deviation left of the mode, > 0.
sigma_right : float
    Standard deviation right of the mode, > 0.
)doc");
  asym.def(bind::strict_init<AsymmetricNormal, double, double, double>("mode", "sigma_left", "sigma_right"),
           py::arg("mode"), py::arg("sigma_left"), py::arg("sigma_right"))
      .def_static(
          "fit", [](const bind::VecArg& samples) { return AsymmetricNormal::fit(samples.get("samples")); },
          py::arg("samples"),
          R"doc(Maximum-likelihood fit (Villani & Larsson 2006 profile likelihood).

For a mode m the ML sigmas are closed-form; the mode minimises S_l^(1/3) + S_r^(1/3) (sums of squared
deviations left / right of m), searched over the samples and refined by golden section.

Parameters
----------
samples : numpy.ndarray
    Shape (n,), n >= 3 finite values, not all equal.

Returns
-------
AsymmetricNormal
)doc")
      .def_property_readonly("mode", &AsymmetricNormal::mode, "Mode.")
      .def_property_readonly("sigma_left", &AsymmetricNormal::sigma_left,
                             "Standard deviation left of the mode.")
      .def_property_readonly("sigma_right", &AsymmetricNormal::sigma_right,
                             "Standard deviation right of the mode.")
      .def(py::pickle(
          [](const AsymmetricNormal& d) { return py::make_tuple(d.mode(), d.sigma_left(), d.sigma_right()); },
          [](const py::tuple& t) {
            return AsymmetricNormal(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>());
          }));
  def_common<AsymmetricNormal>(asym);

  // ---- Beta
  py::class_<Beta> beta(m, "Beta", R"doc(Beta(a, b) distribution on [0, 1].

Quality statistics of Grisales Fig. 2: LOS Beta(4, 1.5), soft NLOS Beta(3, 1.5), hard NLOS Beta(1.5, 4).

Parameters
----------
a : float
    First shape parameter > 0.
b : float
    Second shape parameter > 0.
)doc");
  beta.def(bind::strict_init<Beta, double, double>("a", "b"), py::arg("a"), py::arg("b"))
      .def_property_readonly("a", &Beta::a, "First shape parameter.")
      .def_property_readonly("b", &Beta::b, "Second shape parameter.")
      .def(py::pickle([](const Beta& d) { return py::make_tuple(d.a(), d.b()); },
                      [](const py::tuple& t) { return Beta(t[0].cast<double>(), t[1].cast<double>()); }));
  def_common<Beta>(beta);

  // ---- Empirical
  py::class_<Empirical> empirical(m, "Empirical",
                                  R"doc(Gaussian kernel density of samples (Silverman's bandwidth).

The same density as ``scipy.stats.gaussian_kde(samples, bw_method="silverman")``: bandwidth
h = std(samples, ddof=1) * (3 n / 4)^(-1/5). ``mean()`` is the sample mean and ``variance()`` is
var(samples, ddof=0) + h^2, the variance of the smoothed density.

Parameters
----------
samples : numpy.ndarray
    Shape (n,), n >= 2 finite values with a nonzero spread (unit of x).
)doc");
  empirical
      .def(py::init([](const bind::VecArg& samples) { return Empirical(samples.get("samples")); }),
           py::arg("samples"))
      .def_property_readonly("samples", &Empirical::samples, py::return_value_policy::copy,
                             "The samples, sorted ascending, shape (n,).")
      .def_property_readonly("bandwidth", &Empirical::bandwidth, "Kernel bandwidth h (unit of x).")
      .def_property_readonly("size", &Empirical::size, "Number of samples n.")
      .def(py::pickle([](const Empirical& d) { return py::make_tuple(d.samples()); },
                      [](const py::tuple& t) { return Empirical(bind::to_vector(t[0], "samples")); }));
  def_common<Empirical>(empirical);

  // ---- Distribution
  py::class_<Distribution> dist(m, "Distribution", R"doc(Any of the noise distributions, behind one type.

Every function of nlosloc that takes a Distribution also accepts a Normal, Rayleigh, Exponential, Gev,
TruncatedNormal, ShiftedNormal, AsymmetricNormal, Beta or Empirical directly.

Parameters
----------
dist : Normal | Rayleigh | Exponential | Gev | TruncatedNormal | ShiftedNormal | AsymmetricNormal | Beta | Empirical, optional
    The distribution held; the default is Normal(0, 1).
)doc");
  dist.def(py::init<>())
      .def(py::init<const Normal&>(), py::arg("dist"))
      .def(py::init<const Rayleigh&>(), py::arg("dist"))
      .def(py::init<const Exponential&>(), py::arg("dist"))
      .def(py::init<const Gev&>(), py::arg("dist"))
      .def(py::init<const TruncatedNormal&>(), py::arg("dist"))
      .def(py::init<const ShiftedNormal&>(), py::arg("dist"))
      .def(py::init<const AsymmetricNormal&>(), py::arg("dist"))
      .def(py::init<const Beta&>(), py::arg("dist"))
      .def(py::init<const Empirical&>(), py::arg("dist"))
      .def(py::init<const Distribution&>(), py::arg("dist"))
      .def_property_readonly(
          "value",
          [](const Distribution& d) {
            return std::visit([](const auto& x) { return py::cast(x); }, d.variant());
          },
          "The concrete distribution held (a copy).")
      .def(py::pickle(
          [](const Distribution& d) {
            return py::make_tuple(std::visit([](const auto& x) { return py::cast(x); }, d.variant()));
          },
          [](const py::tuple& t) { return t[0].cast<Distribution>(); }));
  def_common<Distribution>(dist);

  py::implicitly_convertible<Normal, Distribution>();
  py::implicitly_convertible<Rayleigh, Distribution>();
  py::implicitly_convertible<Exponential, Distribution>();
  py::implicitly_convertible<Gev, Distribution>();
  py::implicitly_convertible<TruncatedNormal, Distribution>();
  py::implicitly_convertible<ShiftedNormal, Distribution>();
  py::implicitly_convertible<AsymmetricNormal, Distribution>();
  py::implicitly_convertible<Beta, Distribution>();
  py::implicitly_convertible<Empirical, Distribution>();
}
}  // namespace nlosloc::bind_noise_cpp

void bind_noise(py::module_& m) { nlosloc::bind_noise_cpp::define_module(m); }
