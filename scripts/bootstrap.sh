#!/usr/bin/env bash
# Installs every dependency of nlosloc on a fresh Debian machine (run as root) and creates the
# project virtual environment .venv. Idempotent: a second run only checks and returns quickly.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"

apt_pkgs=(build-essential cmake ninja-build git python3 python3-venv python3-dev
  libeigen3-dev catch2 libboost-math-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  libbenchmark-dev libcereal-dev clang-format)

missing=()
for p in "${apt_pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "[bootstrap] apt-get install ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# Debian's pybind11 2.10 builds modules that crash with numpy 2 (DESIGN.md): it must not be found.
if dpkg-query -W -f='${Status}' pybind11-dev 2>/dev/null | grep -q "install ok installed"; then
  echo "[bootstrap] removing Debian pybind11-dev (incompatible with numpy 2)" >&2
  apt-get remove -y -qq pybind11-dev >/dev/null
fi

py="${NLOSLOC_PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
  echo "[bootstrap] creating .venv" >&2
  "$py" -m venv .venv
fi
stamp=.venv/.nlosloc-requirements
if ! cmp -s requirements-dev.txt "$stamp" 2>/dev/null; then
  echo "[bootstrap] pip install -r requirements-dev.txt" >&2
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -r requirements-dev.txt
  cp requirements-dev.txt "$stamp"
fi
