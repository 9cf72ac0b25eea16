"""The number and bool parameters of the constructors and model functions (motion models,
MeasurementStack rows, sight chains, snapshots, the merge and resampling parts, gcrb_rtoa, custom
scenarios) convert strictly and name themselves (field_value.hpp, strict_fn / strict_method /
StrictArg). pybind11's own casters took True as 1.0 or 1 (ConstantVelocity2(True, 1.0) was a model
with dt = 1 s) and refused 2.0 for an integer with "incompatible function arguments", naming no
argument."""

import numpy as np
import pytest

from nlosloc import bounds, core, mitigation, models, noise, rbpf, sim, situation
from test_rbpf import MOTION as MOTION6
from test_rbpf import P0 as P06
from test_rbpf import QUALITY, SIGHT
from test_rbpf import X0 as X06
from test_rbpf import stack as stack6

ANCHORS = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]])
TWO = [noise.Normal(0.0, 1.0), noise.Normal(2.0, 1.0)]
REAL = r"expected a real number, got "
INT = r"expected an integer, got "


def cv_stack():
    return models.MeasurementStack(models.ConstantVelocity2.layout(), ANCHORS, 2)


def twr_stack():
    return models.MeasurementStack(models.TwoWayClock.layout(), ANCHORS, 2)


def check(call, good, reals=(), ints=(), bools=()):
    """call(**good) works, also with numpy scalars; each named parameter refuses the wrong types
    with a TypeError that names it."""
    call(**good)
    call(
        **{
            k: (np.float32(v) if k in reals else np.int64(v) if k in ints else v)
            for k, v in good.items()
        }
    )
    for name in reals:
        for bad, shown in (
            (True, r"True \(bool\)"),
            ("1", r"'1' \(str\)"),
            (1j, r"1j \(complex\)"),
        ):
            with pytest.raises(TypeError, match=rf"^{name}: {REAL}{shown}$"):
                call(**{**good, name: bad})
    for name in ints:
        for bad, shown in ((True, r"True \(bool\)"), (2.0, r"2.0 \(float\)"), (None, "None")):
            with pytest.raises(TypeError, match=rf"^{name}: {INT}{shown}"):
                call(**{**good, name: bad})
        with pytest.raises(ValueError, match=rf"^{name}: expected an integer in \["):
            call(**{**good, name: 2**70})
    for name in bools:
        with pytest.raises(
            TypeError, match=rf"^{name}: expected a bool \(True or False\), got 1 \(int\)$"
        ):
            call(**{**good, name: 1})


def test_motion_models():
    wa = models.VelocityNoise.WhiteAcceleration
    check(models.ConstantVelocity2, dict(dt=0.1, sigma2=1.0, noise=wa), reals=("dt", "sigma2"))
    check(models.ConstantVelocity3, dict(dt=0.1, sigma2=1.0), reals=("dt", "sigma2"))
    check(
        models.ConstantVelocityClock2,
        dict(dt=0.1, sigma_v2=1.0, sigma_tau2=0.5),
        reals=("dt", "sigma_v2", "sigma_tau2"),
    )
    check(
        models.TwoWayClock,
        dict(h=0.5, sigma_omega=1e-6, sigma_phi=1e-7, sigma_v=0.3),
        reals=("h", "sigma_omega", "sigma_phi", "sigma_v"),
    )
    m = models.ConstantVelocity2(np.float32(0.5), 2)
    assert m.dt == 0.5 and m.sigma2 == 2.0 and m.noise == models.VelocityNoise.RandomWalk
    with pytest.raises(TypeError, match=r"^noise: expected VelocityNoise, got 1 \(int\)$"):
        models.ConstantVelocity2(0.1, 1.0, 1)


def test_measurement_stack_rows():
    layout = models.ConstantVelocity2.layout()
    check(
        models.MeasurementStack,
        dict(layout=layout, anchors=ANCHORS, num_conditions=2),
        ints=("num_conditions",),
    )
    s = cv_stack()
    rows = s.rows
    check(lambda **a: cv_stack().add_toa(**a), dict(anchor=1, noise=TWO), ints=("anchor",))
    check(lambda **a: cv_stack().add_aoa(**a), dict(anchor=1, noise=TWO), ints=("anchor",))
    check(
        lambda **a: cv_stack().add_aoa_phase(**a),
        dict(anchor=1, sector_center=0.5, noise=TWO),
        ints=("anchor",),
        reals=("sector_center",),
    )
    check(
        lambda **a: cv_stack().add_tdoa(**a),
        dict(anchor_a=1, anchor_b=0, noise_a=TWO, noise_b=TWO),
        ints=("anchor_a", "anchor_b"),
    )
    check(
        lambda **a: cv_stack().add_linear(**a),
        dict(h=[1.0, 0.0, 0.0, 0.0], anchor=2, noise=TWO),
        ints=("anchor",),
    )
    check(
        lambda **a: twr_stack().add_twr(**a),
        dict(anchor=1, slot=1, delta_slot=1e-3, reply_delay=2e-4, sigma_m=1e-9, gamma=[None, None]),
        ints=("anchor", "slot"),
        reals=("delta_slot", "reply_delay", "sigma_m"),
    )
    # a refused row adds nothing; add_toa(True, ...) was a row of anchor 1
    with pytest.raises(TypeError, match=rf"^anchor: {INT}True"):
        s.add_toa(True, TWO)
    assert s.rows == rows
    s.add_toa(np.int32(2), TWO)
    assert s.rows == rows + 1 and s.row(rows).anchor == 2


def test_sight_chains():
    w = dict(w=1.5, dt=0.5, mean_los=20.0, mean_nlos=10.0)
    check(situation.speed_transition_single, w, reals=tuple(w))
    check(situation.speed_transition_multiple, w, reals=tuple(w))
    check(
        situation.speed_transition_memoryless,
        dict(mean_los=20.0, mean_nlos=10.0),
        reals=("mean_los", "mean_nlos"),
    )
    np.testing.assert_array_equal(
        situation.speed_transition_multiple(np.float32(1.5), 0.5, 20, 10),
        situation.speed_transition_multiple(1.5, 0.5, 20.0, 10.0),
    )
    check(
        situation.SightModel.fixed,
        dict(transition=[[0.9, 0.1], [0.2, 0.8]], k_sight=3),
        ints=("k_sight",),
    )
    check(
        situation.SightModel.speed_dependent,
        dict(mean_los=20.0, mean_nlos=10.0, dt=0.5),
        reals=("mean_los", "mean_nlos", "dt"),
    )
    model = situation.SightModel.speed_dependent(20.0, 10.0, 0.5)
    check(situation.SightProcess, dict(model=model, num_anchors=3), ints=("num_anchors",))
    with pytest.raises(TypeError, match=r"^model: expected SightModel, got 3 \(int\)$"):
        situation.SightProcess(3, 2)
    g = np.array([[0.7, 0.3], [0.4, 0.6]])
    check(
        situation.ForwardFilterSnapshot,
        dict(gamma=g, pred=g, k=4, log_evidence=-1.5),
        ints=("k",),
        reals=("log_evidence",),
    )


def test_snapshots():
    f = rbpf.Rbpf(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, rbpf.RbpfOptions(num_particles=4))
    s = f.save()
    fields = (
        "situations means covs log_weights situation_probabilities estimate covariance time step"
    ).split()
    check(rbpf.RbpfSnapshot, {k: getattr(s, k) for k in fields}, reals=("time",), ints=("step",))
    opt = rbpf.PfOptions(num_particles=50, seed=3)
    p = rbpf.ParticleFilter(MOTION6, stack6(), SIGHT, QUALITY, X06, P06, opt).save()
    fields = (
        "particles situations log_weights situation_probabilities estimate covariance "
        "position_variance generators time step"
    ).split()
    check(
        rbpf.PfSnapshot,
        {k: getattr(p, k) for k in fields},
        reals=("position_variance", "time"),
        ints=("step",),
    )


def test_merge_and_resampling_parts():
    check(
        rbpf.default_merge_threshold,
        dict(position_variance=4.0, num_particles=8),
        reals=("position_variance",),
        ints=("num_particles",),
    )
    check(
        rbpf.merge_greedy,
        dict(
            keys=[0, 0],
            means=[[0.0, 0.1]],
            logw=[-1.0, -2.0],
            d_min=0.5,
            with_pairs=False,
            threads=1,
        ),
        reals=("d_min",),
        ints=("threads",),
        bools=("with_pairs",),
    )
    check(rbpf.select_top, dict(logw=[-1.0, -2.0, -0.5], M=2), ints=("M",))
    check(rbpf.systematic_resample, dict(w=[0.5, 0.5], M=4, u0=0.3), ints=("M",), reals=("u0",))
    check(
        rbpf.situation_count,
        dict(num_conditions=2, num_anchors=3),
        ints=("num_conditions", "num_anchors"),
    )
    check(rbpf.encode_situation, dict(sight=[1, 0, 1], num_conditions=2), ints=("num_conditions",))
    check(
        rbpf.decode_situation,
        dict(key=5, num_conditions=2, num_anchors=3),
        ints=("num_conditions", "num_anchors"),
    )


def test_other_parameters():
    check(core.Rng(3).normal, dict(mu=1.0, sigma=2.0), reals=("mu", "sigma"))
    assert core.Rng(3).normal() == core.Rng(3).normal(0, 1)  # the no-argument overload still works
    check(
        bounds.gcrb_rtoa,
        dict(anchors=ANCHORS, position=[3.0, 4.0], Q=np.eye(3), sigma_tau2=1.0),
        reals=("sigma_tau2",),
    )
    check(mitigation.make_box_qp, dict(n=3, solver="enumeration"), ints=("n",))

    def generate(case_index, steps, rng):
        raise AssertionError("not called")

    check(
        sim.CustomScenario,
        dict(
            name="strict-args",
            measurements=cv_stack().add_toa(0, TWO),
            cases=["a"],
            steps=10,
            dt=0.5,
            generate=generate,
            discard=2,
        ),
        reals=("dt",),
        ints=("steps", "discard"),
    )
