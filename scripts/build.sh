#!/usr/bin/env bash
# Installs the Debian dependencies (if missing) and builds everything in ./build (Release).
# SLAMDUNK_SKIP_TEST_DIRS="a;b": test folders left out (scripts/test.sh sets it for CI's Release
# tree); unset, every test is built.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
skip=${SLAMDUNK_SKIP_TEST_DIRS:-}
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DSLAMDUNK_SKIP_TEST_DIRS="$skip"
elif ! grep -qxF "SLAMDUNK_SKIP_TEST_DIRS:STRING=$skip" build/CMakeCache.txt; then
  cmake -S . -B build -DSLAMDUNK_SKIP_TEST_DIRS="$skip"
fi
cmake --build build -j"$(nproc)"
