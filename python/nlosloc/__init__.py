"""nlosloc: NLOS-robust radio localisation (TOA, RTOA, TDOA, AOA, two-way ranging).

The compiled extension ``nlosloc._core`` is split into submodules, re-exported here and importable
as ``nlosloc.core``, ``nlosloc.noise``, ``nlosloc.models``, ``nlosloc.filters`` and ``nlosloc.sim``
(``from nlosloc.filters import Ukf`` works). ``nlosloc.plots`` (needs matplotlib, the ``plots``
extra) and ``nlosloc.montecarlo`` are pure-Python modules, imported on demand.
"""

from __future__ import annotations

import sys as _sys

from nlosloc import _core, _params, _pickle  # noqa: F401  (keyword constructors and reprs; pickling)
from nlosloc._core import (
    bounds,
    core,
    filters,
    mitigation,
    models,
    noise,
    rbpf,
    sim,
    situation,
    snapshot,
)

__version__: str = _core.__version__

__all__ = [
    "bounds",
    "core",
    "filters",
    "mitigation",
    "models",
    "noise",
    "rbpf",
    "sim",
    "situation",
    "snapshot",
]

# pybind11 submodules are attributes of _core, not entries of sys.modules; register them so that
# `import nlosloc.filters` and `from nlosloc._core.filters import X` both work.
for _name, _mod in (
    ("core", core),
    ("noise", noise),
    ("models", models),
    ("filters", filters),
    ("sim", sim),
    ("situation", situation),
    ("rbpf", rbpf),
    ("snapshot", snapshot),
    ("mitigation", mitigation),
    ("bounds", bounds),
):
    _sys.modules.setdefault(f"{__name__}.{_name}", _mod)
    _sys.modules.setdefault(f"{__name__}._core.{_name}", _mod)
del _name, _mod
