#!/usr/bin/env bash
# Builds nlosloc-bench (Release, build/demo) and runs the K1 scenario: 100 Monte Carlo runs, seed 1,
# results in build/demo/k1.json (the table beside the paper's numbers on stdout, progress on stderr).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
bash scripts/bootstrap.sh
cmake -S . -B build/demo -G Ninja -DCMAKE_BUILD_TYPE=Release -DNLOSLOC_BUILD_TESTS=OFF \
  -DNLOSLOC_BUILD_BENCH=ON -DNLOSLOC_BUILD_PYTHON=OFF
cmake --build build/demo --target nlosloc-bench -j "${NLOSLOC_JOBS:-$(nproc)}"
build/demo/bench/nlosloc-bench run K1 --runs 100 --seed 1 --json build/demo/k1.json
echo "[demo] results: build/demo/k1.json" >&2
