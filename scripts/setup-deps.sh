#!/usr/bin/env bash
# Installs the Debian packages gyrodrift builds against. Idempotent and quiet when all is there.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config ccache
  libeigen3-dev libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libsvm-dev libfann-dev libjs-dygraphs
  clang libclang-rt-14-dev
  libtomlplusplus-dev
  # The Python package (python/, docs/python.md): bindings, tests, the Dask fleet runner, examples.
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
  python3-dask python3-distributed python3-matplotlib
  # pip install . (pyproject.toml, setup.py): pip and the setuptools build backend.
  python3-pip python3-setuptools
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "gyrodrift: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq >/dev/null
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
