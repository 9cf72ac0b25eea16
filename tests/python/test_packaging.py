"""The installed package: version, submodules, typing markers."""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.resources
import types

import pytest

import nlosloc

SUBMODULES = [
    "core",
    "noise",
    "models",
    "situation",
    "filters",
    "rbpf",
    "snapshot",
    "mitigation",
    "bounds",
    "sim",
]


def test_version() -> None:
    assert nlosloc.__version__ == "0.1.0"
    # One version everywhere: CMake project(), pyproject.toml, the compiled module.
    assert importlib.metadata.version("nlosloc") == nlosloc.__version__
    assert nlosloc._core.__version__ == nlosloc.__version__


def test_all_lists_the_compiled_submodules() -> None:
    assert sorted(nlosloc.__all__) == sorted(SUBMODULES)


@pytest.mark.parametrize("name", SUBMODULES)
def test_submodule_imports(name: str) -> None:
    mod = importlib.import_module(f"nlosloc.{name}")
    assert isinstance(mod, types.ModuleType)
    assert mod is getattr(nlosloc, name)
    assert mod is getattr(nlosloc._core, name)
    assert mod.__doc__, f"nlosloc.{name} has no docstring"


def test_from_import_of_submodule() -> None:
    from nlosloc import filters as f1
    from nlosloc._core import filters as f2

    assert f1 is f2


def test_star_import() -> None:
    ns: dict[str, object] = {}
    exec("from nlosloc import *", ns)
    assert set(SUBMODULES) <= ns.keys()


def test_typing_markers_installed() -> None:
    root = importlib.resources.files("nlosloc")
    assert root.joinpath("py.typed").is_file(), "py.typed is missing from the installed package"
    stubs = root.joinpath("_core.pyi").is_file() or root.joinpath("_core", "__init__.pyi").is_file()
    assert stubs, "the _core stubs are not installed (run scripts/gen_stubs.sh)"
