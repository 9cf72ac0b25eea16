"""
Per-epoch solvers and baselines: MLE-LOS, CHEN, CONG, URR.
"""
from __future__ import annotations
__all__: list[str] = list()
