"""Reprs (nlosloc/_params.py): parameters and options print as the constructor call that rebuilds
them, floats as Python prints them (no digits lost), records as their fields; no signature shows a
default as ``<... object at 0x...>``."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

import nlosloc
from nlosloc import _params, _pickle, core, filters, mitigation, noise, rbpf, sim, snapshot

MODULES = [
    "core",
    "models",
    "noise",
    "filters",
    "situation",
    "rbpf",
    "mitigation",
    "snapshot",
    "bounds",
    "sim",
]


def namespace() -> dict[str, object]:
    ns: dict[str, object] = {"array": np.array, "inf": math.inf, "nan": math.nan}
    for m in MODULES:
        ns.update(vars(importlib.import_module(f"nlosloc.{m}")))
    return ns


@pytest.mark.parametrize("cls", _pickle._PARAMS, ids=lambda c: c.__name__)
def test_parameters_print_as_the_constructor_call_that_rebuilds_them(cls: type) -> None:
    p = cls()
    text = repr(p)
    assert text.startswith(f"{cls.__name__}(") and "object at 0x" not in text
    back = eval(text, namespace())  # noqa: S307  (the repr of our own class)
    assert type(back) is cls
    assert repr(back) == text
    fields = _pickle._fields(p)
    assert set(fields) == set(_params._field_names(cls, writable_only=True))
    for k, v in fields.items():
        got = getattr(back, k)
        if isinstance(v, np.ndarray):
            np.testing.assert_array_equal(got, v)
        elif type(v) in _pickle._PARAMS:  # nested parameters compare by their own fields
            assert repr(got) == repr(v), k
        else:
            assert got == v, k


def test_parameters_take_their_fields_as_keywords() -> None:
    o = snapshot.GaussNewtonOptions(max_iterations=50, step_tolerance=1e-9)
    assert (o.max_iterations, o.step_tolerance) == (50, 1e-9)
    assert o.initial_damping == snapshot.GaussNewtonOptions().initial_damping
    h = sim.H2Params(steps=300, quality_los_a=2.0)
    assert (h.steps, h.quality_los_a, h.dt) == (300, 2.0, sim.H2Params().dt)
    with pytest.raises(
        TypeError, match=r"GaussNewtonOptions\(\): no field 'max_iter'; its fields: "
    ):
        snapshot.GaussNewtonOptions(max_iter=5)
    with pytest.raises(TypeError, match=r"keywords only, got 1 positional argument$"):
        snapshot.GaussNewtonOptions(5)
    # a field's own setter checks it, as when it is set afterwards
    with pytest.raises(TypeError):
        mitigation.QpBiasEkfOptions(gamma="wide")
    # the extension's own keyword constructors stay
    assert rbpf.RbpfOptions(num_particles=7).num_particles == 7
    assert rbpf.PfOptions(seed=9).seed == 9


def test_a_float_prints_every_digit_it_has() -> None:
    o = rbpf.RbpfOptions(num_particles=64, merge_threshold=1.25e-7, threads=2)
    o.scheme = core.SigmaScheme.scaled(1e-7, 2.5, 0.0)
    text = repr(o)
    assert "merge_threshold=1.25e-07" in text
    assert (
        "scheme=SigmaScheme(kind=SigmaScheme.Kind.Scaled, alpha=1e-07, beta=2.5, kappa=0.0)" in text
    )
    assert "variant=RbpfVariant.Reordered" in text and "noise_form=NoiseForm.Additive" in text
    back = eval(text, namespace())  # noqa: S307
    assert back.merge_threshold == 1.25e-7 and back.scheme == o.scheme and back.num_particles == 64
    # nested parameters: the K2 study's base K1 parameters
    k2 = sim.K2Params()
    k2.base.sigma_los = 0.1 + 0.2
    assert "sigma_los=0.30000000000000004" in repr(k2)
    assert eval(repr(k2), namespace()).base.sigma_los == 0.1 + 0.2  # noqa: S307


def test_the_value_records_keep_every_digit() -> None:
    s = core.SigmaScheme(core.SigmaScheme.Kind.Huerta, 1e-4, 3.0, 0.0)
    assert repr(s) == "SigmaScheme(kind=SigmaScheme.Kind.Huerta, alpha=0.0001, beta=3.0, kappa=0.0)"
    assert eval(repr(s), namespace()) == s  # noqa: S307
    w = core.SigmaScheme.scaled(1e-3).weights(2)
    assert repr(w) == (
        f"SigmaWeights(gamma={w.gamma!r}, wm0={w.wm0!r}, wc0={w.wc0!r}, wi={w.wi!r})"
    )
    assert (
        repr(snapshot.RowNoise(0.5, 1e-8, 2.0))
        == "RowNoise(center=0.5, sigma_left=1e-08, sigma_right=2.0)"
    )
    m = nlosloc.models
    ukf = filters.Ukf(
        m.ConstantVelocity2(0.1, 1.0),
        _toa_stack(),
        np.array([1.0, 2.0, 0.0, 0.0]),
        np.eye(4),
        core.SigmaScheme.scaled(0.5),
    )
    r = ukf.step(np.array([5.0, 6.0, 7.0]), np.zeros(3, dtype=int))
    ll, jitter = r.log_likelihood, r.jitter
    head = f"StepResult(log_likelihood={ll!r}, rows_used=3"
    assert repr(r) == f"{head}, status=CholeskyStatus.Ok, jitter={jitter!r})"


def _toa_stack() -> nlosloc.models.MeasurementStack:
    m = nlosloc.models
    anchors = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
    stack = m.MeasurementStack(m.ConstantVelocity2.layout(), anchors, 2)
    for b in range(3):
        stack.add_toa(b, [noise.Normal(0.0, 1.0), noise.Normal(3.0, 2.0)])
    return stack


def test_records_print_their_fields() -> None:
    motion = nlosloc.models.ConstantVelocity2(0.1, 1.0)
    sight = nlosloc.situation.SightProcess(
        nlosloc.situation.SightModel.speed_dependent(10.0, 10.0, 0.1), 3
    )
    quality = nlosloc.situation.QualityModel([noise.Beta(4.0, 1.5), noise.Beta(1.5, 4.0)])
    f = rbpf.Rbpf(
        motion,
        _toa_stack(),
        sight,
        quality,
        np.array([1.0, 2.0, 0.0, 0.0]),
        np.eye(4),
        rbpf.RbpfOptions(num_particles=8),
    )
    info = f.step(np.array([2.5, 9.0, 8.5]), np.array([0.9, 0.8, 0.2]))
    text = repr(info)
    names = [
        "log_likelihood",
        "offspring",
        "ukf_runs",
        "merged",
        "failures",
        "merge_threshold",
        "status",
    ]
    assert (
        text
        == "RbpfStepInfo("
        + ", ".join(f"{k}={_params._value_repr(getattr(info, k))}" for k in names)
        + ")"
    )
    assert f"log_likelihood={info.log_likelihood!r}" in text and "offspring=8" in text
    assert "status=CholeskyStatus." in text
    fix = snapshot.LosSolver(_toa_stack()).solve(np.array([2.5, 9.0, 8.5]), np.array([1.0, 2.0]))
    assert repr(fix).startswith("Fix(theta=array([") and f"cost={fix.cost!r}" in repr(fix)
    qp = mitigation.make_box_qp(2, solver="enumeration").solve(
        np.eye(2), np.array([1.0, -1.0]), np.zeros(2), np.full(2, 5.0)
    )
    assert "object at 0x" not in repr(qp) + repr(fix)


def test_no_signature_shows_an_object_address() -> None:
    found = []
    for m in MODULES:
        mod = importlib.import_module(f"nlosloc.{m}")
        for name, obj in vars(mod).items():
            members = [obj] + (
                [getattr(obj, a) for a in vars(obj)] if isinstance(obj, type) else []
            )
            for c in members:
                doc = getattr(c, "__doc__", None) or ""
                if "object at 0x" in doc:
                    found.append(f"{m}.{name}")
    assert found == []
