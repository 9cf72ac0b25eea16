"""Every field of the option and parameter classes converts strictly and names itself when it
refuses a value (python/src/field_value.hpp), and so do the time arguments t and t0 and the
keyword constructors of the extension. pybind11's own conversion took None and 0.5 as True/False
for a bool field and True as 1.0 for a number, and refused a wrong type with "incompatible
function arguments", which names no field. A refused value leaves the field as it was."""

from fractions import Fraction

import numpy as np
import pytest

from nlosloc import core, filters, mitigation, models, noise, rbpf, snapshot
from nlosloc._pickle import _PARAMS, _field_names
from test_filters_api import MOTION, P0, X0, stack
from test_rbpf import MOTION as MOTION6
from test_rbpf import P0 as P06
from test_rbpf import QUALITY, SIGHT
from test_rbpf import X0 as X06
from test_rbpf import stack as stack6

# fields kept on UInt64Arg, whose messages name the bare field (test_input_checks)
UINT64_FIELDS = {("RbpfOptions", "max_offspring"), ("PfOptions", "seed")}


def fields_of(kind):
    out = []
    for cls in _PARAMS:
        obj = cls()
        for name in _field_names(cls):
            v = getattr(obj, name)
            if (cls.__name__, name) in UINT64_FIELDS:
                continue
            if type(v) is kind:
                out.append((cls, name))
    return out


def ids(cases):
    return [f"{c.__name__}.{n}" for c, n in cases]


BOOLS, FLOATS, INTS = fields_of(bool), fields_of(float), fields_of(int)


def test_every_kind_of_field_is_covered():
    # the classes of _PARAMS hold 9 bool, 71 float and 33 int fields (2 more on UInt64Arg)
    assert len(BOOLS) >= 9 and len(FLOATS) >= 71 and len(INTS) >= 33


def refused(obj, name, value, exc, message):
    before = getattr(obj, name)
    with pytest.raises(exc, match=rf"^{type(obj).__name__}\.{name}: {message}"):
        setattr(obj, name, value)
    after = getattr(obj, name)
    assert after == before and type(after) is type(before)


@pytest.mark.parametrize(("cls", "name"), BOOLS, ids=ids(BOOLS))
def test_bool_fields(cls, name):
    o = cls()
    for v in (None, 0.5, 1, 0, "yes", np.float64(1.0), np.array([True])):
        msg = r"expected a bool \(True or False\), got "
        if isinstance(v, np.ndarray):
            msg = r"expected a bool \(True or False\), got a 1-D array"
        refused(o, name, v, TypeError, msg)
    for v, want in ((False, False), (True, True), (np.bool_(False), False), (np.array(True), True)):
        setattr(o, name, v)
        assert getattr(o, name) is want


@pytest.mark.parametrize(("cls", "name"), FLOATS, ids=ids(FLOATS))
def test_float_fields(cls, name):
    o = cls()
    wrong = (True, np.bool_(False), 1 + 2j, np.complex64(1.0), "1.5", None, [1.0], np.array([1.0]))
    for v in wrong:
        refused(o, name, v, TypeError, "expected a real number")
    refused(o, name, True, TypeError, r"expected a real number, got True \(bool\)$")
    refused(o, name, 10**400, ValueError, "expected a real number within the range of a double")
    right = ((3, 3.0), (np.float32(2.5), 2.5), (np.array(0.25), 0.25), (Fraction(1, 8), 0.125))
    for v, want in right:
        setattr(o, name, v)
        assert getattr(o, name) == want and type(getattr(o, name)) is float


@pytest.mark.parametrize(("cls", "name"), INTS, ids=ids(INTS))
def test_int_fields(cls, name):
    o = cls()
    for v in (True, 2.0, np.float64(2.0), "3", None):
        refused(o, name, v, TypeError, "expected an integer, got ")
    refused(o, name, 2.5, TypeError, r"expected an integer, got 2\.5 \(float\)$")
    for v in (2**70, -(2**70)):
        refused(o, name, v, ValueError, rf"expected an integer in \[-?\d+, \d+\], got {v}$")
    for v in (np.int64(5), np.uint8(5), np.array(5), 5):
        setattr(o, name, v)
        assert getattr(o, name) == 5 and type(getattr(o, name)) is int


def test_int_field_ranges_are_the_cpp_types():
    o = rbpf.RbpfOptions()
    int_range = r"expected an integer in \[-2147483648, 2147483647\], got 2147483648$"
    refused(o, "num_particles", 2**31, ValueError, int_range)
    o.num_particles = 2**31 - 1
    assert o.num_particles == 2**31 - 1


def test_enum_and_struct_fields_name_themselves():
    o = rbpf.RbpfOptions()
    refused(o, "variant", 1.5, TypeError, r"expected RbpfVariant, got 1\.5 \(float\)$")
    refused(o, "noise_form", rbpf.RbpfVariant.Classical, TypeError, "expected NoiseForm, got ")
    refused(o, "scheme", "cubature", TypeError, "expected SigmaScheme, got 'cubature' \\(str\\)$")
    o.scheme = core.SigmaScheme.cubature()
    assert o.scheme == core.SigmaScheme.cubature()
    q = mitigation.QpBiasEkfOptions()
    with pytest.raises(
        TypeError, match=r"^QpBiasEkfOptions\.noise: expected RangeNoise, got 50\.0 "
    ):
        q.noise = 50.0
    # the getter still returns the field itself: setting through it changes the options
    q.noise.sigma0 = 7.0
    assert q.noise.sigma0 == 7.0
    with pytest.raises(TypeError, match=r"^RangeNoise\.sigma0: expected a real number, got None"):
        q.noise.sigma0 = None
    assert q.noise.sigma0 == 7.0


def test_keyword_constructors_convert_strictly():
    # the extension's own keyword constructors (RbpfOptions, PfOptions, RangeNoise, RowNoise,
    # SigmaScheme) and the Python one of the other classes (through the setters)
    cases = (
        (lambda: rbpf.RbpfOptions(merge=None), r"^merge: expected a bool \(True or False\)"),
        (lambda: rbpf.RbpfOptions(num_particles=8.0), r"^num_particles: expected an integer"),
        (lambda: rbpf.RbpfOptions(threads=True), r"^threads: expected an integer, got True"),
        (lambda: rbpf.RbpfOptions(variant=0.0), r"^variant: expected RbpfVariant"),
        (lambda: rbpf.PfOptions(ess_threshold=1j), r"^ess_threshold: expected a real number"),
        (lambda: rbpf.PfOptions(resampling="x"), r"^resampling: expected PfResampling"),
        (lambda: mitigation.RangeNoise(sigma0=True), r"^sigma0: expected a real number, got True"),
        (lambda: snapshot.RowNoise(0.0, "1", 1.0), r"^sigma_left: expected a real number"),
        (lambda: core.SigmaScheme(alpha=None), r"^alpha: expected a real number, got None"),
        (lambda: core.SigmaScheme(kind=1), r"^kind: expected Kind, got 1 \(int\)"),
        (lambda: mitigation.QpBiasEkfOptions(mitigate=0), r"^QpBiasEkfOptions\.mitigate: expected"),
    )
    for make, msg in cases:
        with pytest.raises(TypeError, match=msg):
            make()
    assert rbpf.RbpfOptions(num_particles=np.int64(8), merge=np.bool_(False)).merge is False
    assert rbpf.PfOptions(ess_threshold=1).ess_threshold == 1.0
    assert core.SigmaScheme(alpha=np.float32(0.5)).alpha == 0.5
    with pytest.raises(TypeError):  # an int argument still refuses a bool, now UInt64Arg too
        rbpf.PfOptions(seed=True)


def test_setters_of_row_noise_and_bias_estimator():
    r = snapshot.RowNoise(0.0, 1.0, 2.0)
    refused(r, "sigma_left", True, TypeError, r"expected a real number, got True \(bool\)$")
    with pytest.raises(ValueError, match="sigma_left"):  # the model's own check
        r.sigma_left = -1.0
    assert r.sigma_left == 1.0
    e = mitigation.BiasEstimator(np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]]))
    refused(e, "sparsity", 1j, TypeError, "expected a real number")
    refused(e, "soft_threshold", None, TypeError, "expected a real number, got None")


def test_time_arguments_are_real_numbers():
    f = filters.Ukf(MOTION, stack(), X0, P0, t0=np.float64(1.5))
    assert f.time == 1.5
    for make in (
        lambda: filters.Ukf(MOTION, stack(), X0, P0, t0=True),
        lambda: filters.Ekf(MOTION, stack(), X0, P0, t0="0"),
        lambda: rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, t0=1j),
    ):
        with pytest.raises(TypeError, match=r"^t0: expected a real number, got "):
            make()
    before = (f.mean.copy(), f.time)
    with pytest.raises(TypeError, match=r"^t: expected a real number, got True \(bool\)$"):
        f.set_belief(X0, P0, t=True)
    assert np.array_equal(f.mean, before[0]) and f.time == before[1]
    f.set_belief(X0, P0, t=2)
    assert f.time == 2.0
    s = stack()
    with pytest.raises(TypeError, match=r"^t: expected a real number, got None"):
        s.predict(X0, t=None)
    np.testing.assert_array_equal(s.predict(X0, t=0), s.predict(X0))
    assert isinstance(models.StateLayout().dim, int)


def test_distribution_constructors_and_sizes_are_strict():
    # pybind11 took Normal(0.0, True) as std 1 and refused Normal("0", 1.0) without a name
    makers = (
        (noise.Normal, ("mean", "std"), (0.0, 2.0)),
        (noise.Rayleigh, ("scale",), (2.0,)),
        (noise.Exponential, ("mean",), (2.0,)),
        (noise.Gev, ("shape", "loc", "scale"), (0.1, 0.0, 2.0)),
        (noise.TruncatedNormal, ("mu", "sigma", "lower", "upper"), (0.0, 1.0, -1.0, 2.0)),
        (noise.ShiftedNormal, ("shift", "std"), (1.0, 2.0)),
        (noise.AsymmetricNormal, ("mode", "sigma_left", "sigma_right"), (0.0, 1.0, 2.0)),
        (noise.Beta, ("a", "b"), (2.0, 3.0)),
    )
    for cls, names, good in makers:
        assert repr(cls(*good)) == repr(cls(*[np.float32(v) if v != 0.1 else v for v in good]))
        for i, name in enumerate(names):
            for bad, shown in (
                (True, r"True \(bool\)"),
                ("1", r"'1' \(str\)"),
                (1j, r"1j \(complex\)"),
            ):
                args = list(good)
                args[i] = bad
                with pytest.raises(
                    TypeError, match=rf"^{name}: expected a real number, got {shown}$"
                ):
                    cls(*args)
    r = core.Rng(4)
    for call, name in (
        (r.normals, "n"),
        (r.below, "n"),
        (core.BatchRng(r).bits, "n_quads"),
        (core.BatchRng(r).uniforms, "n"),
        (core.BatchRng(r).normals, "n"),
    ):
        for bad in (True, 4.0, None):
            with pytest.raises(TypeError, match=rf"^{name}: expected an integer, got "):
                call(bad)
        with pytest.raises(ValueError, match=rf"^{name}: expected an integer in \["):
            call(2**70)
    with pytest.raises(
        ValueError, match=r"^n: expected an integer in \[0, 18446744073709551615\], got -1$"
    ):
        r.below(-1)
    assert core.Rng(4).normals(np.int64(3)).shape == (3,)
