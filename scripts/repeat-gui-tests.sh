#!/usr/bin/env bash
# Every test of windows (the ctest label `viewers`: the live viewer's tests, --gui on both apps
# (GuiApps.*), MRPT's own viewers), N times in a row beside BUSY_LOOPS busy loops (default 2),
# which starve the idle-priority window threads as a loaded CI machine does: a failure that
# shows once in a few whole suites shows here. Stops at the first failing repeat and says how
# many repeats passed before it; exit 0 only if all N passed.
# The tests of a repeat run all at once (each with its own Xvfb), so that they also load one
# another: a repeat takes about two minutes beside two busy loops on 2 cores, where one test
# after the other took about fifteen (the idle-priority window threads wait for CPU, not for
# one another).
#   scripts/repeat-gui-tests.sh N [BUSY_LOOPS]
#   JOBS=1 scripts/repeat-gui-tests.sh 5     (ctest -j1: one test at a time)
#   EXCLUDE='^MrptViewers\.' scripts/repeat-gui-tests.sh 5   (ctest -E: leave some tests out)
# Needs the Release tree (scripts/build.sh). The test data (ctest's prepare_test_data fixture)
# is prepared once before the busy loops start. A test that would skip (no data, no X server,
# a tool missing) fails here, as in CI (SLAMDUNK_REQUIRE_DATA=1): a skipped repeat proves nothing.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { echo "usage: scripts/repeat-gui-tests.sh N [BUSY_LOOPS]" >&2; exit 2; }
if [ $# -lt 1 ] || [ $# -gt 2 ]; then usage; fi
repeats=$1
busy=${2:-2}
[[ "$repeats" =~ ^[1-9][0-9]*$ ]] || usage
[[ "$busy" =~ ^[0-9]+$ ]] || usage
build=${BUILD_DIR:-build}
[ -f "$build/CTestTestfile.cmake" ] || {
  echo "repeat-gui-tests: no test tree in $build (scripts/build.sh first)" >&2
  exit 1
}
export SLAMDUNK_REQUIRE_DATA=${SLAMDUNK_REQUIRE_DATA:-1}
exclude=()
[ -n "${EXCLUDE:-}" ] && exclude=(-E "$EXCLUDE")

tests=$(ctest --test-dir "$build" -N -L viewers "${exclude[@]}" | sed -n 's/^ *Test *#[0-9]*: //p' |
  grep -v '^prepare_test_data$' || true)
count=$(printf '%s\n' "$tests" | grep -c . || true)
if ! printf '%s\n' "$tests" | grep -q '^GuiApps\.'; then
  echo "repeat-gui-tests: no GuiApps.* test under the label 'viewers' in $build" >&2
  exit 1
fi
jobs=${JOBS:-$count}
[[ "$jobs" =~ ^[1-9][0-9]*$ ]] || usage
echo "repeat-gui-tests: $count tests (label viewers), $repeats repeats beside $busy busy loops," \
  "$jobs at a time"

# The data first, without the busy loops; the repeats then leave the fixture out (-FA).
ctest --test-dir "$build" -R '^prepare_test_data$' --output-on-failure >/dev/null || {
  echo "repeat-gui-tests: preparing the test data failed (ctest -R prepare_test_data)" >&2
  exit 1
}

pids=()
stop_busy() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
}
trap stop_busy EXIT
for _ in $(seq "$busy"); do
  (while :; do :; done) &
  pids+=($!)
done

passed=0
for i in $(seq "$repeats"); do
  start=$SECONDS
  if ctest --test-dir "$build" -L viewers "${exclude[@]}" -FA '.*' -j "$jobs" \
    --no-tests=error --output-on-failure; then
    passed=$((passed + 1))
    echo "repeat-gui-tests: repeat $i of $repeats passed ($((SECONDS - start)) s)"
  else
    echo "repeat-gui-tests: repeat $i of $repeats FAILED; $passed of $repeats repeats passed" \
      "before it (beside $busy busy loops)" >&2
    exit 1
  fi
done
echo "repeat-gui-tests: all $passed of $repeats repeats passed (beside $busy busy loops)"
