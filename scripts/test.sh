#!/usr/bin/env bash
# The whole test suite: installs dependencies, builds, runs every test with ctest.
# Real recordings are taken from ../shared/data (override with SLAMDUNK_DATA_DIR); tests that
# need them skip with a message when they are absent.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
