#!/usr/bin/env bash
# The long fuzzing run: RUNS mutated inputs (default 10000) for every reader of outside data
# (rawlog, map, ini, tum-list, tum-trajectory, depth-png), from the seed corpus in
# tests/fuzz/corpus. Uses the sanitizer tree build-asan (scripts/sanitize.sh) when it exists,
# else ./build; SLAMDUNK_FUZZ_BUILD=DIR picks another tree. Failing inputs go to
# DIR/fuzz-crashes/ (replay one: fuzz-readers TARGET --replay FILE).
#   scripts/fuzz.sh              10000 inputs per reader, seed 1
#   scripts/fuzz.sh 50000 7      50000 inputs per reader, seed 7
# Exit status 0 only if no input crashed, hung, ran out of memory, made a sanitizer report or
# was rejected without an error naming the file.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
runs=${1:-10000}
seed=${2:-1}
if [ -n "${SLAMDUNK_FUZZ_BUILD:-}" ]; then
  build=$SLAMDUNK_FUZZ_BUILD
elif [ -f build-asan/CMakeCache.txt ]; then
  build=build-asan
else
  build=build
  [ -f build/CMakeCache.txt ] || bash scripts/build.sh
fi
case $build in /*) ;; *) build=$root/$build ;; esac

logs=$build/fuzz-logs
crashes=$build/fuzz-crashes
rm -rf "$logs"
mkdir -p "$logs" "$crashes"
# Sanitizer reports (if the tree has them) go to files, printed at the end. A length field that
# makes a reader allocate more than 2 GiB is reported as a failure, not left to the OOM killer.
# intercept_tls_get_addr=0: see scripts/sanitize.sh (LeakSanitizer's tracer crash at exit).
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:max_allocation_size_mb=2048:intercept_tls_get_addr=0:log_path=$logs/asan"
export LSAN_OPTIONS="suppressions=$root/scripts/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$logs/ubsan"

cmake --build "$build" --target fuzz-readers
fuzz=$build/bin/fuzz-readers
corpus=$root/tests/fuzz/corpus

status=0
summary=()
for target in rawlog map ini tum-list tum-trajectory depth-png; do
  extra=()
  [ "$target" = ini ] && extra=(--corpus "$root/config-ini" --corpus "$root/config-ini/cameras")
  # Slower sanitized code: a generous per-input time limit still catches real hangs.
  if "$fuzz" "$target" --runs "$runs" --seed "$seed" --timeout 60 --corpus "$corpus/$target" \
      "${extra[@]}" --crashes "$crashes" >"$logs/$target.out" 2>"$logs/$target.err"; then
    :
  else
    status=1
    echo "fuzz: $target FAILED (last lines of $logs/$target.err):" >&2
    tail -n 20 "$logs/$target.err" >&2
  fi
  line=$(grep "^fuzz-readers $target:" "$logs/$target.out" | head -n 1 || true)
  echo "${line:-fuzz-readers $target: no summary (crashed?)}"
  summary+=("${line:-$target: no summary}")
done

reports=$(find "$logs" -name 'asan*' -o -name 'ubsan*' | sort)
if [ -n "$reports" ]; then
  status=1
  echo "fuzz: sanitizer report(s):" >&2
  for f in $reports; do
    echo "===== $f" >&2
    cat "$f" >&2
  done
fi
echo "fuzz: tree $build, $runs inputs per reader, seed $seed: $([ $status = 0 ] && echo OK || echo FAILURES, inputs in $crashes)"
exit $status
