"""Pickling (copyreg) of the scenario parameters and scenarios, the options and settings of every
filter, tracker and baseline, the sigma-point schemes and the motion models, so that they travel to
other processes (``montecarlo.run(executor=...)``: a factory that closes over them) and can be saved
with an experiment.

A parameter or options object pickles as its class and the values of all its read-write properties
(every field: one added later is included without a change here; nested settings such as
``QpBiasEkfOptions.noise`` pickle the same way), and is checked as usual where it is used; a
scenario pickles as its class and its parameters; a sigma-point scheme as its rule and parameters;
a motion model as its constructor's arguments; a measurement stack as its layout, anchors and the
add_* calls that rebuild its rows; a sight chain, a sight process and a quality model as what built
them (the noise distributions pickle in the extension module); a Kalman filter (Kf, Ekf, Ukf,
UkfAugmented) as its models and its belief at its time, which is its whole state: the copy steps
on exactly as the original; the forward filter of the sight and the IUKF likewise, with the
forward filter's probabilities, step and evidence; a built-in box-QP solver (``make_box_qp``) as
its kind, size, settings and the active set its next solve starts from (the BoxQp class pickles
itself); the Ke & Wu trackers as their models, options, belief at their time and a copy of their
solver (``QpBiasEkf``: your own solver object must pickle too; ``BiasAugmentedEkf``: the whole
augmented belief, biases included), so the copy steps on exactly as the original; only the last
update's report (``bias``, ``last_step``, ``nlos_detected``) starts empty, until the next update
(``copy.deepcopy`` keeps it). The Rbpf pickles as its models, options and ``save()`` snapshot
(particles, weights, summaries, time and step: the copy steps on bit for bit as the original); the
joint ``ParticleFilter`` likewise, its snapshot holding its threads' random generators too (the
generators ``core.Rng`` and ``core.BatchRng`` pickle in the extension module, as their state words).
"""

from __future__ import annotations

import copyreg
from typing import Any

from nlosloc._core import core as _core
from nlosloc._core import filters as _filters
from nlosloc._core import mitigation as _mitigation
from nlosloc._core import models as _models
from nlosloc._core import rbpf as _rbpf
from nlosloc._core import sim as _sim
from nlosloc._core import situation as _situation
from nlosloc._core import snapshot as _snapshot

_PARAMS = (
    _sim.H1Params,
    _sim.H2Params,
    _sim.K1Params,
    _sim.K2Params,
    _sim.K3Params,
    _rbpf.RbpfOptions,
    _rbpf.PfOptions,
    _mitigation.BoxQpSettings,
    _mitigation.RangeNoise,
    _mitigation.QpBiasEkfOptions,
    _mitigation.BiasAugmentedEkfOptions,
    _snapshot.GaussNewtonOptions,
    _snapshot.ChenOptions,
    _snapshot.CongOptions,
    _snapshot.UrruelaOptions,
    _models.StateLayout,
)
_SCENARIOS = (_sim.H1, _sim.H2, _sim.K1, _sim.K2, _sim.K3)


def _field_names(cls: type, writable_only: bool = True) -> list[str]:
    """The class's properties (only those with a setter when writable_only), in the order the class
    defines them (a pybind11 class's __dict__ keeps it); also the reprs' fields (_params)."""
    return [
        k
        for k, a in vars(cls).items()
        if isinstance(a, property) and (a.fset is not None or not writable_only)
    ]


def _fields(obj: Any) -> dict[str, Any]:
    return {k: getattr(obj, k) for k in _field_names(type(obj))}


def _make_params(cls: type, fields: dict[str, Any]) -> Any:
    p = cls()
    for k, v in fields.items():
        setattr(p, k, v)
    return p


def _reduce_params(p: Any) -> tuple[Any, ...]:
    return _make_params, (type(p), _fields(p))


def _reduce_scenario(s: Any) -> tuple[Any, ...]:
    return type(s), (s.params,)


for _cls in _PARAMS:
    copyreg.pickle(_cls, _reduce_params)
for _cls in _SCENARIOS:
    copyreg.pickle(_cls, _reduce_scenario)


def _reduce_scheme(s: Any) -> tuple[Any, ...]:
    # The constructor takes the four fields as they are: a factory would reset the ones its kind
    # fixes (huerta's beta), which a scheme built from its fields may set otherwise.
    return type(s), (s.kind, s.alpha, s.beta, s.kappa)


def _reduce_row_noise(r: Any) -> tuple[Any, ...]:
    return type(r), (r.center, r.sigma_left, r.sigma_right)


def _reduce_cv(m: Any) -> tuple[Any, ...]:
    return type(m), (m.dt, m.sigma2, m.noise)


def _reduce_cvc(m: Any) -> tuple[Any, ...]:
    return type(m), (m.dt, m.sigma_v2, m.sigma_tau2)


def _reduce_twr(m: Any) -> tuple[Any, ...]:
    return type(m), (m.dt, m.sigma_omega, m.sigma_phi, m.sigma_v)


copyreg.pickle(_core.SigmaScheme, _reduce_scheme)
copyreg.pickle(_snapshot.RowNoise, _reduce_row_noise)
copyreg.pickle(_models.TwoWayClock, _reduce_twr)
for _cls in (_models.ConstantVelocity2, _models.ConstantVelocity3):
    copyreg.pickle(_cls, _reduce_cv)
for _cls in (_models.ConstantVelocityClock2, _models.ConstantVelocityClock3):
    copyreg.pickle(_cls, _reduce_cvc)


def _stack_rows(m: Any) -> list[tuple[Any, ...]]:
    """The add_* calls that rebuild the rows of a MeasurementStack, in order."""
    kind = _models.RowKind
    nz = m.num_conditions
    rows: list[tuple[Any, ...]] = []
    for i in range(m.rows):
        r = m.row(i)
        if r.kind == kind.TwrT:
            continue  # the second row of the pair add_twr made
        if r.kind == kind.TwrTau:
            w = m.twr_params(i)
            twr = (w.delta_slot, w.reply_delay, w.sigma_m, w.gamma)
            rows.append(("add_twr", r.anchor, r.slot, *twr))
            continue
        noise = [m.noise(i, z) for z in range(nz)]
        if r.kind == kind.Tdoa:
            noise_b = [m.noise_b(i, z) for z in range(nz)]
            rows.append(("add_tdoa", r.anchor, r.anchor2, noise, noise_b))
        elif r.kind == kind.AoaPhase:
            rows.append(("add_aoa_phase", r.anchor, r.sector_center, noise))
        elif r.kind == kind.Linear:
            rows.append(("add_linear", m.linear_h(i), r.anchor, noise))
        else:
            method = {kind.Toa: "add_toa", kind.Rtoa: "add_rtoa", kind.Aoa: "add_aoa"}[r.kind]
            rows.append((method, r.anchor, noise))
    return rows


def _make_stack(layout: Any, anchors: Any, num_conditions: int, rows: list[tuple[Any, ...]]) -> Any:
    m = _models.MeasurementStack(layout, anchors, num_conditions)
    for method, *args in rows:
        getattr(m, method)(*args)
    return m


def _reduce_stack(m: Any) -> tuple[Any, ...]:
    return _make_stack, (m.layout, m.anchors, m.num_conditions, _stack_rows(m))


def _make_sight_model(speed: bool, args: tuple[Any, ...]) -> Any:
    make = _situation.SightModel.speed_dependent if speed else _situation.SightModel.fixed
    return make(*args)


def _reduce_sight_model(s: Any) -> tuple[Any, ...]:
    if s.is_speed_dependent:
        return _make_sight_model, (True, (s.mean_los, s.mean_nlos, s.dt, s.form, s.initial))
    return _make_sight_model, (False, (s.base_matrix, s.k_sight, s.initial))


def _reduce_sight_process(p: Any) -> tuple[Any, ...]:
    return type(p), ([p.model(b) for b in range(p.num_anchors)],)


def _reduce_quality(q: Any) -> tuple[Any, ...]:
    return type(q), ([q.distribution(z) for z in range(q.num_conditions)],)


copyreg.pickle(_models.MeasurementStack, _reduce_stack)
copyreg.pickle(_situation.SightModel, _reduce_sight_model)
copyreg.pickle(_situation.SightProcess, _reduce_sight_process)
copyreg.pickle(_situation.QualityModel, _reduce_quality)


def _reduce_kf(f: Any) -> tuple[Any, ...]:
    return type(f), (f.motion, f.H, f.R, f.mean, f.cov, f.time)


def _reduce_ekf(f: Any) -> tuple[Any, ...]:
    return type(f), (f.motion, f.measurements, f.mean, f.cov, f.time)


def _reduce_ukf(f: Any) -> tuple[Any, ...]:
    return type(f), (f.motion, f.measurements, f.mean, f.cov, f.scheme, f.time)


copyreg.pickle(_filters.Kf, _reduce_kf)
copyreg.pickle(_filters.Ekf, _reduce_ekf)
copyreg.pickle(_filters.Ukf, _reduce_ukf)
copyreg.pickle(_filters.UkfAugmented, _reduce_ukf)


def _reduce_forward_snapshot(s: Any) -> tuple[Any, ...]:
    return type(s), (s.gamma, s.pred, s.k, s.log_evidence)


def _make_forward(process: Any, quality: Any, snapshot: Any) -> Any:
    f = _situation.ForwardFilter(process, quality)
    f.restore(snapshot)
    return f


def _reduce_forward(f: Any) -> tuple[Any, ...]:
    return _make_forward, (f.process, f.quality, f.save())


def _make_iukf(args: tuple[Any, ...], snapshot: Any) -> Any:
    f = _rbpf.Iukf(*args)
    f.forward.restore(snapshot)
    return f


def _reduce_iukf(f: Any) -> tuple[Any, ...]:
    fw = f.forward
    args = (f.motion, f.measurements, fw.process, fw.quality, f.mean, f.cov, f.scheme, f.time)
    return _make_iukf, (args, fw.save())


copyreg.pickle(_situation.ForwardFilterSnapshot, _reduce_forward_snapshot)
copyreg.pickle(_situation.ForwardFilter, _reduce_forward)
copyreg.pickle(_rbpf.Iukf, _reduce_iukf)


def _reduce_qp_bias_ekf(f: Any) -> tuple[Any, ...]:
    args = (f.motion, f.anchors, f.mean, f.cov, f.options, f.solver, f.time)
    return type(f), args


def _make_bias_augmented(args: tuple[Any, ...], mean: Any, cov: Any, time: float) -> Any:
    f = _mitigation.BiasAugmentedEkf(*args)
    f.set_augmented_belief(mean, cov, time)
    return f


def _reduce_bias_augmented(f: Any) -> tuple[Any, ...]:
    args = (f.motion, f.anchors, f.mean[:4], f.cov[:4, :4], f.options, f.time)
    return _make_bias_augmented, (args, f.mean, f.cov, f.time)


copyreg.pickle(_mitigation.QpBiasEkf, _reduce_qp_bias_ekf)
copyreg.pickle(_mitigation.BiasAugmentedEkf, _reduce_bias_augmented)


def _reduce_rbpf_snapshot(s: Any) -> tuple[Any, ...]:
    fields = (s.situations, s.means, s.covs, s.log_weights, s.situation_probabilities)
    return type(s), (*fields, s.estimate, s.covariance, s.time, s.step)


def _make_rbpf(args: tuple[Any, ...], snapshot: Any) -> Any:
    f = _rbpf.Rbpf(*args)
    f.restore(snapshot)
    return f


def _reduce_rbpf(f: Any) -> tuple[Any, ...]:
    s = f.save()
    args = (
        f.motion,
        f.measurements,
        f.sight_process,
        f.quality,
        s.estimate,
        s.covariance,
        f.options,
    )
    return _make_rbpf, (args, s)


copyreg.pickle(_rbpf.RbpfSnapshot, _reduce_rbpf_snapshot)
copyreg.pickle(_rbpf.Rbpf, _reduce_rbpf)


def _reduce_pf_snapshot(s: Any) -> tuple[Any, ...]:
    fields = (s.particles, s.situations, s.log_weights, s.situation_probabilities, s.estimate)
    return type(s), (*fields, s.covariance, s.position_variance, s.generators, s.time, s.step)


def _make_pf(args: tuple[Any, ...], snapshot: Any) -> Any:
    f = _rbpf.ParticleFilter(*args)
    f.restore(snapshot)
    return f


def _reduce_pf(f: Any) -> tuple[Any, ...]:
    s = f.save()
    n = len(s.estimate)
    # The snapshot replaces the constructor's draw: any belief it accepts will do (the particle
    # set's own covariance may be singular).
    identity = [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    args = (f.motion, f.measurements, f.sight_process, f.quality, s.estimate, identity, f.options)
    return _make_pf, (args, s)


copyreg.pickle(_rbpf.PfSnapshot, _reduce_pf_snapshot)
copyreg.pickle(_rbpf.ParticleFilter, _reduce_pf)
