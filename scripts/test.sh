#!/usr/bin/env bash
# The project's test command (also .ci/run). Stops at the first failure.
#   1. scripts/bootstrap.sh (system packages, .venv)
#   2. The two builds side by side: the Python package (`pip install --no-build-isolation .` into .venv,
#      a regular, non-editable install: the wheel is built incrementally in build/<wheel_tag>, the build
#      deps come from .venv; -Werror on) in the background, its output in build/pip-install.log, while
#      C++ is configured and built in build/test (Ninja, Release, tests + bench, NLOSLOC_WERROR=ON, unity
#      batches of the tests: NLOSLOC_UNITY_TESTS=ON). Both are CPU-bound; run one after the other, each
#      leaves a core idle through its last compiles and the extension's link.
#   3. ctest (no C++ test imports nlosloc, so it may run while the wheel is still building); then the
#      wheel's exit status and log, then pytest (which includes the stub drift test)
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

step "Python package (pip install --no-build-isolation ., in the background: build/pip-install.log)"
mkdir -p build
pip_log=build/pip-install.log
# setsid: its own process group, so that stopping it stops its cmake, ninja and compilers too.
NLOSLOC_WERROR=ON CMAKE_BUILD_PARALLEL_LEVEL="$jobs" setsid \
  .venv/bin/python -m pip install --no-build-isolation --no-deps --force-reinstall . >"$pip_log" 2>&1 &
pip_pid=$!
# Whatever stops this script (a failed step, Ctrl-C) stops the background build with it.
stop_pip() { [ -n "${pip_pid:-}" ] && kill -- "-$pip_pid" 2>/dev/null || true; }
trap stop_pip EXIT

step "C++ build (build/test)"
cmake -S . -B build/test -G Ninja -DCMAKE_BUILD_TYPE=Release -DNLOSLOC_BUILD_TESTS=ON \
  -DNLOSLOC_BUILD_BENCH=ON -DNLOSLOC_BUILD_PYTHON=OFF -DNLOSLOC_WERROR=ON -DNLOSLOC_UNITY_TESTS=ON
cmake --build build/test -j "$jobs"

step "C++ tests (ctest)"
ctest --test-dir build/test --output-on-failure -j2 --no-tests=error

step "Python package: waiting for pip install (its output follows)"
pip_rc=0
wait "$pip_pid" || pip_rc=$?
pip_pid=
cat "$pip_log" >&2
if [ "$pip_rc" -ne 0 ]; then
  echo "pip install failed with exit code $pip_rc (log: $pip_log)" >&2
  exit "$pip_rc"
fi

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
