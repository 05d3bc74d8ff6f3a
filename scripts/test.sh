#!/usr/bin/env bash
# The whole test suite: installs dependencies, builds, runs every test with ctest, then the same
# suite under AddressSanitizer + UndefinedBehaviorSanitizer (scripts/sanitize.sh, ./build-asan).
# Real recordings are taken from ../shared/data (override with SLAMDUNK_DATA_DIR); tests that
# need them skip with a message when they are absent.
#   scripts/test.sh [CTEST_ARGS...]       (e.g. -R SlamdunkLive: both runs take the arguments)
#   SLAMDUNK_SKIP_SANITIZERS=1 scripts/test.sh   (the Release suite only: a developer's quick run)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
if [ "${SLAMDUNK_SKIP_SANITIZERS:-0}" = 1 ]; then
  echo "test.sh: sanitizer suite skipped (SLAMDUNK_SKIP_SANITIZERS=1)"
else
  bash scripts/sanitize.sh "$@"
fi
