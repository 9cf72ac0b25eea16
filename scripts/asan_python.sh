#!/usr/bin/env bash
# The Python tests against an extension built with AddressSanitizer and UBSan (not in the default test
# run: the build takes about 11 minutes on 2 cores). Run scripts/bootstrap.sh (or scripts/test.sh) first.
#   1. builds nlosloc._core at -O1 with -fsanitize=address,undefined into build/asan-python (no LTO;
#      warnings are not errors: GCC 12 reports false -Wmaybe-uninitialized in libstdc++ under ASan);
#   2. copies python/nlosloc with that extension into build/asan-python/pkg;
#   3. runs pytest with the sanitizer runtimes preloaded (the interpreter itself is not instrumented) and
#      that package first on PYTHONPATH. Leak checks are off: CPython keeps its objects at exit.
# Extra arguments go to pytest (e.g. -k rbpf).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
[ -x .venv/bin/python ] || { echo "asan_python.sh: no .venv; run scripts/bootstrap.sh first" >&2; exit 2; }
jobs="${NLOSLOC_JOBS:-$(nproc)}"
out=build/asan-python
san="-O1 -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B "$out" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="$san" \
  -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_INTERPROCEDURAL_OPTIMIZATION=OFF \
  -DNLOSLOC_BUILD_TESTS=OFF -DNLOSLOC_BUILD_BENCH=OFF -DNLOSLOC_BUILD_PYTHON=ON \
  -DPython_EXECUTABLE="$here/.venv/bin/python"
cmake --build "$out" -j "$jobs"
rm -rf "$out/pkg"
mkdir -p "$out/pkg"
cp -r python/nlosloc "$out/pkg/"
cp "$out"/_core.*.so "$out/pkg/nlosloc/"
preload="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"
LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 PYTHONPATH="$here/$out/pkg" \
  .venv/bin/python -m pytest -q -p no:cacheprovider tests/python "$@"
