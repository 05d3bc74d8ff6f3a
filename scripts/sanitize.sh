#!/usr/bin/env bash
# The test suite under AddressSanitizer (with LeakSanitizer) and UndefinedBehaviorSanitizer:
# builds ./build-asan (RelWithDebInfo, SLAMDUNK_ASAN + SLAMDUNK_UBSAN) and runs ctest there.
# Any sanitizer report fails the run, also one from a tool a test runs (slamdunk-rawlog,
# tum2rawlog, ...), which a test expecting that tool to fail could otherwise mistake for the
# failure it expects: ASan/LSan reports go to build-asan/sanitizer-logs/ and are printed at the
# end; UBSan (combined with ASan, GCC's runtime ignores log_path) prints to stderr and aborts,
# and tests/common's runCommand() fails the test on any report in a tool's output.
#   scripts/sanitize.sh                   the whole suite (scripts/test.sh runs this in CI)
#   scripts/sanitize.sh -R SlamdunkLive   extra arguments go to ctest
# Leaks inside third-party libraries are suppressed in scripts/sanitizers/lsan.supp (each entry
# says why); a report in this project's code is a bug to fix, not to suppress.
# RelWithDebInfo (-O2): compiling took about as long as at -O1 here (one Eigen-heavy file: 51 s
# vs 47 s with both sanitizers), and the suite is mostly optimized Eigen code, far slower at -O1.
# Measured on the 2-core CI machine shared with two other builds (load 6-8): build 42.5 min from
# scratch; rendering the test rawlogs under ASan took 26 min (now hard-linked, see below).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=build-asan
bash scripts/install-deps.sh

logs=$root/$build/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
# Exported for the build too: gtest_discover_tests runs every test binary while building.
# log_path: one file per process that reported (asan.<pid>).
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:check_initialization_order=1:strict_init_order=1:log_path=$logs/asan"
export LSAN_OPTIONS="suppressions=$root/scripts/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"

reports() {  # prints every sanitizer report; fails if there is one
  local files
  files=$(find "$logs" -type f | sort)
  [ -z "$files" ] && return 0
  echo "sanitize: $(echo "$files" | wc -l) sanitizer report(s):" >&2
  for f in $files; do
    echo "===== $f" >&2
    cat "$f" >&2
  done
  return 1
}

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSLAMDUNK_ASAN=ON -DSLAMDUNK_UBSAN=ON
fi
# The rawlogs the application tests share (tests/apps/prepare-test-data.sh): taken from the
# Release tree when it has them (scripts/test.sh runs the Release suite first), hard-linked, not
# copied. Rendering them again under ASan took 26 minutes; the tools that make
# them (synthetic-rgbd, tum2rawlog) still run under the sanitizers in their own tests.
if [ -d build/test-data ] && [ ! -e "$build/test-data" ]; then
  mkdir -p "$build"
  cp -al build/test-data "$build/test-data" ||
    { rm -rf "$build/test-data"; cp -a build/test-data "$build/test-data"; }
fi
start=$SECONDS
cmake --build "$build" -j"$(nproc)" || { reports || true; exit 1; }
built=$SECONDS

status=0
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" "$@" || status=$?
echo "sanitize: build $((built - start)) s, tests $((SECONDS - built)) s"
reports || status=1
exit $status
