#!/usr/bin/env bash
# The long runs CI leaves out (about four hours on 2 cores); run them before every update of the
# README's results tables and after any change to the viewer, the live pipeline or the readers:
#   1. the whole Release suite, the 2.5-minute hand-held scans included (SLAMDUNK_LONG_TESTS=1
#      renders them: about 2 GB more in build/test-data);
#   2. the whole suite under ASan + UBSan (scripts/sanitize.sh --all);
#   3. every GUI and live-viewer test 50 times in a row beside two busy loops, all of a repeat
#      at once (scripts/repeat-gui-tests.sh: about an hour and a half);
#   4. 10000 fuzzed inputs per reader (scripts/fuzz.sh) and a 30-minute soak (scripts/soak.sh).
# Missing data fails here as in CI (SLAMDUNK_REQUIRE_DATA=1).
#   scripts/test-long.sh             all four
#   scripts/test-long.sh 1 3         only the steps named
set -euo pipefail
cd "$(dirname "$0")/.."
export SLAMDUNK_REQUIRE_DATA=1 SLAMDUNK_LONG_TESTS=1
steps=("$@")
[ ${#steps[@]} -eq 0 ] && steps=(1 2 3 4)

status=0
run_step() {  # run_step N COMMAND...: runs it, times it, remembers a failure
  local n=$1 start=$SECONDS
  shift
  echo "=== test-long: step $n: $*"
  if "$@"; then
    echo "=== test-long: step $n passed in $((SECONDS - start)) s"
  else
    echo "=== test-long: step $n FAILED after $((SECONDS - start)) s"
    status=1
  fi
}

for step in "${steps[@]}"; do
  case $step in
  1)
    bash scripts/build.sh
    run_step 1 ctest --test-dir build --output-on-failure -j"$(nproc)"
    ;;
  2) run_step 2 bash scripts/sanitize.sh --all ;;
  3) run_step 3 bash scripts/repeat-gui-tests.sh 50 2 ;;
  4)
    run_step 4 bash scripts/fuzz.sh
    run_step 4 bash scripts/soak.sh
    ;;
  *)
    echo "test-long: no step '$step' (1-4)" >&2
    exit 2
    ;;
  esac
done
exit $status
