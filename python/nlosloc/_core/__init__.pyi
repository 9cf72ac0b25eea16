"""
nlosloc compiled core (private; use the nlosloc package and its submodules).
"""
from __future__ import annotations
from . import core
from . import noise
from . import models
from . import situation
from . import filters
from . import rbpf
from . import snapshot
from . import mitigation
from . import bounds
from . import sim
__all__: list[str] = ['bounds', 'core', 'filters', 'mitigation', 'models', 'noise', 'rbpf', 'sim', 'situation', 'snapshot']
__version__: str = '0.1.0'
