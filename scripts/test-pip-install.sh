#!/usr/bin/env bash
# `pip install --no-build-isolation .` into a temporary prefix, then the pytest suite against the
# installed package (not the build tree's). Run by CTest as python.pip_install with the suite's
# own build folder (GYRODRIFT_CMAKE_BUILD_DIR), so the install builds nothing new.
# Usage: scripts/test-pip-install.sh SOURCE_DIR BUILD_DIR PYTHON
set -euo pipefail
src=$1 build=$2 python=$3
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cd "$src"
GYRODRIFT_CMAKE_BUILD_DIR="$build" "$python" -m pip install --no-build-isolation --no-deps \
  --no-index --no-cache-dir --disable-pip-version-check --root-user-action=ignore -q \
  --prefix "$prefix" .
site=$(dirname "$(find "$prefix" -path '*/gyrodrift/__init__.py' -print -quit)")
[ -f "$site/_gyrodrift"*.so ] || { echo "no compiled module installed under $prefix" >&2; exit 1; }
site=$(dirname "$site")
# The package imported must be the installed one.
PYTHONPATH="$site" "$python" -c "import sys, gyrodrift; sys.exit(0 if gyrodrift.__file__.startswith('$prefix') else 'imported ' + gyrodrift.__file__)"
cd "$prefix"  # away from the source tree, whose python/ folder must not be imported
PYTHONPATH="$site" PYTHONDONTWRITEBYTECODE=1 "$python" -m pytest -q -p no:cacheprovider "$src/python/tests"
