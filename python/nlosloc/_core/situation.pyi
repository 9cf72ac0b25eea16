"""
Sight (LOS/NLOS) Markov models, quality likelihoods, HMM filter.
"""
from __future__ import annotations
__all__: list[str] = list()
