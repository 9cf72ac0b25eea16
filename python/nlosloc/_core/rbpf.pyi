"""
Rao-Blackwellized particle filters with merge/prune, joint PF.
"""
from __future__ import annotations
__all__: list[str] = list()
