#!/usr/bin/env bash
# The project's test command (also .ci/run). Stops at the first failure.
#   1. scripts/bootstrap.sh (system packages, .venv)
#   2. C++: configure + build build/test (Ninja, Release, tests + bench, NLOSLOC_WERROR=ON, unity batches
#      of the tests: NLOSLOC_UNITY_TESTS=ON), ctest
#   3. Python: `pip install --no-build-isolation .` into .venv (a regular, non-editable install: the
#      wheel is built incrementally in build/<wheel_tag>, the build deps come from .venv; -Werror on),
#      then pytest (which includes the stub drift test)
#   4. formatting: clang-format and ruff format as diffs (nothing is rewritten), ruff check
# Env: NLOSLOC_JOBS  parallel build jobs (default: nproc)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
jobs="${NLOSLOC_JOBS:-$(nproc)}"
# Each step's header carries the seconds since the start, so a slow CI run shows which step grew.
step() { printf '\n==== %s (at %d s)\n' "$*" "$SECONDS" >&2; }

step "bootstrap"
bash scripts/bootstrap.sh

step "C++ build (build/test)"
cmake -S . -B build/test -G Ninja -DCMAKE_BUILD_TYPE=Release -DNLOSLOC_BUILD_TESTS=ON \
  -DNLOSLOC_BUILD_BENCH=ON -DNLOSLOC_BUILD_PYTHON=OFF -DNLOSLOC_WERROR=ON -DNLOSLOC_UNITY_TESTS=ON
cmake --build build/test -j "$jobs"

step "C++ tests (ctest)"
ctest --test-dir build/test --output-on-failure -j2 --no-tests=error

step "Python package (pip install --no-build-isolation .)"
NLOSLOC_WERROR=ON CMAKE_BUILD_PARALLEL_LEVEL="$jobs" .venv/bin/python -m pip install --no-build-isolation --no-deps \
  --force-reinstall .

step "Python tests (pytest)"
.venv/bin/python -m pytest -q

step "formatting (clang-format, ruff)"
cxx_dirs=()
for d in include src tests/cpp tests/nomalloc tests/consumer bench examples python/src; do
  [ -d "$d" ] && cxx_dirs+=("$d")
done
mapfile -t cxx_files < <(find "${cxx_dirs[@]}" -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.h' \) | sort)
unformatted=()
for f in "${cxx_files[@]}"; do
  if ! clang-format --style=file "$f" | diff -u --label "$f" --label "$f (clang-format)" "$f" -; then
    unformatted+=("$f")
  fi
done
if [ ${#unformatted[@]} -gt 0 ]; then
  echo "clang-format: ${#unformatted[@]} file(s) differ (fix: clang-format -i ${unformatted[*]})" >&2
  exit 1
fi
.venv/bin/ruff format --check --diff python tests/python tests/cli bench examples
.venv/bin/ruff check python tests/python tests/cli bench examples

step "all checks passed"
