"""Shared pytest fixtures for the nlosloc Python tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]


def pytest_report_header(config: pytest.Config) -> str:
    try:
        import nlosloc
    except ImportError as exc:  # reported by the tests themselves
        return f"nlosloc: not importable ({exc})"
    return f"nlosloc {nlosloc.__version__} from {Path(nlosloc.__file__).parent}"


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The source tree (tests read committed files such as the stubs from it)."""
    return REPO_ROOT


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded numpy generator, fresh for every test."""
    return np.random.default_rng(20240607)
