"""Keyword constructors and reprs for the parameter, options and settings classes, and reprs for the
small value classes and result records (a sigma-point scheme and its weights, a step's report, a
fix, a bias estimate, a summary), which pybind11 would print as ``<... object at 0x...>``.

A parameter class (``_pickle._PARAMS``) takes any of its fields as keywords:
``GaussNewtonOptions(max_iterations=50)`` is ``GaussNewtonOptions()`` with that field set, through
the field's own setter (so with its own checks); an unknown keyword or a positional argument is a
TypeError naming it. ``RbpfOptions`` and ``PfOptions`` keep their constructors from the extension,
which take every field as a keyword already.

Each of these classes and records prints as its class name and its fields in the order the class
declares them, every float as Python prints it (the shortest text that reads back as the same
number), enums by name. For a parameter class that is the constructor call that rebuilds it:
``eval`` of the repr, with the module's names and numpy's ``array`` in scope, gives an object with
the same fields; likewise for ``SigmaScheme`` and ``RowNoise``, whose constructors take their
fields. The other records' fields are read-only: their repr is for reading.
"""

from __future__ import annotations

from typing import Any

from nlosloc._core import bounds as _bounds
from nlosloc._core import core as _core
from nlosloc._core import filters as _filters
from nlosloc._core import mitigation as _mitigation
from nlosloc._core import models as _models
from nlosloc._core import rbpf as _rbpf
from nlosloc._core import sim as _sim
from nlosloc._core import snapshot as _snapshot
from nlosloc._pickle import _PARAMS, _field_names

_RECORDS = (
    _core.SigmaScheme,
    _core.SigmaWeights,
    _filters.StepResult,
    _snapshot.RowNoise,
    _rbpf.RbpfStepInfo,
    _rbpf.PfStepInfo,
    _mitigation.MitigationStep,
    _mitigation.BiasEstimate,
    _mitigation.QpResult,
    _mitigation.ReferencePoint,
    _snapshot.Fix,
    _bounds.GcrbResult,
    _models.TwrParams,
    _sim.CaseSummary,
    _sim.EstimatorSummary,
)


def _value_repr(v: Any) -> str:
    # pybind11 enums print as "<RbpfVariant.Reordered: 1>"; by name they read as the value itself
    # (qualified: SigmaScheme.Kind.Scaled).
    if hasattr(type(v), "__members__") and hasattr(v, "name"):
        return f"{type(v).__qualname__}.{v.name}"
    return repr(v)


def _install_repr(cls: type, names: list[str]) -> None:
    def __repr__(self: Any) -> str:
        fields = ", ".join(f"{k}={_value_repr(getattr(self, k))}" for k in names)
        return f"{type(self).__name__}({fields})"

    cls.__repr__ = __repr__  # type: ignore[method-assign]


def _only_default_constructor(cls: type) -> bool:
    doc = cls.__init__.__doc__ or ""
    return doc.splitlines()[0].startswith(f"__init__(self: {cls.__module__}.{cls.__qualname__}) ->")


def _install_keywords(cls: type, names: list[str]) -> None:
    construct = cls.__init__

    def __init__(self: Any, *args: Any, **fields: Any) -> None:
        if args:
            raise TypeError(
                f"{cls.__name__}(): takes its fields as keywords only, got {len(args)} "
                f"positional argument{'s' if len(args) > 1 else ''}"
            )
        for k in fields:
            if k not in names:
                raise TypeError(f"{cls.__name__}(): no field '{k}'; its fields: {', '.join(names)}")
        construct(self)
        for k, v in fields.items():
            setattr(self, k, v)

    __init__.__doc__ = (
        f"{cls.__name__}(**fields): the defaults, with any of the fields ({', '.join(names)}) "
        "set by keyword."
    )
    cls.__init__ = __init__  # type: ignore[method-assign]


for _cls in _PARAMS:
    _names = _field_names(_cls, writable_only=True)
    if _only_default_constructor(_cls):
        _install_keywords(_cls, _names)
    _install_repr(_cls, _names)
for _cls in _RECORDS:
    _install_repr(_cls, _field_names(_cls, writable_only=False))
