"""Pickling of the scenario parameters and scenarios (copyreg), so that a scenario built with custom
parameters travels to other processes (``montecarlo.run(executor=...)``) and can be saved.

A parameter object pickles as its class and the values of all its read-write properties (every
field: one added later is included without a change here), and is checked as usual when a scenario
is built from it; a scenario pickles as its class and its parameters.
"""

from __future__ import annotations

import copyreg
from typing import Any

from nlosloc._core import sim as _sim

_PARAMS = (_sim.H1Params, _sim.H2Params, _sim.K1Params, _sim.K2Params, _sim.K3Params)
_SCENARIOS = (_sim.H1, _sim.H2, _sim.K1, _sim.K2, _sim.K3)


def _fields(obj: Any) -> dict[str, Any]:
    cls = type(obj)
    return {
        k: getattr(obj, k)
        for k in dir(cls)
        if isinstance(getattr(cls, k, None), property) and getattr(cls, k).fset is not None
    }


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
