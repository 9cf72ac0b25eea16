"""
Ke and Wu QP-bias EKF, bias-augmented EKF, QP adapter.
"""
from __future__ import annotations
__all__: list[str] = list()
