#!/usr/bin/env bash
# The test suite under AddressSanitizer (with LeakSanitizer), and with UndefinedBehaviorSanitizer
# for the whole suite. Any sanitizer report fails the run, also one from a tool a test runs
# (slamdunk-rawlog, tum2rawlog, ...), which a test expecting that tool to fail could otherwise
# mistake for the failure it expects: ASan/LSan reports go to <tree>/sanitizer-logs/ and are
# printed at the end; UBSan (combined with ASan, GCC's runtime ignores log_path) prints to stderr
# and aborts, and tests/common's runCommand() fails the test on any report in a tool's output.
#   scripts/sanitize.sh                   CI's subset (named below), ASan at -O1 in ./build-asan
#   scripts/sanitize.sh --all             every test, ASan + UBSan at -O2 in ./build-asan-all
#                                         (about an hour and a half on 2 cores; test-long.sh)
#   scripts/sanitize.sh -R LiveViewer     extra arguments go to ctest
# Leaks inside third-party libraries are suppressed in scripts/sanitizers/lsan.supp (each entry
# says why); a report in this project's code is a bug to fix, not to suppress.
# CI's subset compiles at -O1 with ASan alone: 1.2 times the Release build's CPU time, where
# adding UBSan took 1.9 times and both at -O2 2.9 times (user seconds of Tracker.cpp and
# test_ransac.cpp). Debug information -g1 (line tables, no variables): reports still name file
# and line of every frame, inlined ones too, and the objects stay small for the links.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
bash scripts/install-deps.sh

all=0
if [ "${1:-}" = --all ]; then
  all=1
  shift
fi
build=build-asan
[ $all = 1 ] && build=build-asan-all
logs=$root/$build/sanitizer-logs
rm -rf "$logs"
mkdir -p "$logs"
# Exported for the build too: gtest_discover_tests runs every test binary while building.
# log_path: one file per process that reported (asan.<pid>).
# intercept_tls_get_addr=0: GCC 12's runtime (up to GCC 13) takes a dynamic TLS block whose
# address is 16 bytes past a page boundary for a pre-2.25 glibc one and reads a bogus range
# from the two words before it; LeakSanitizer's tracer then segfaults at exit ("Tracer caught
# signal 11") after the test had passed: by chance, now and then (a CI run failed on two
# synthetic-renderer tests that way, both passing their bodies). LLVM's runtime had the same
# check up to LLVM 16, hence the same option in fuzz.sh. Without the interception LSan does not
# scan dynamic TLS (that of dlopen'ed libraries) for pointers; no leak report came of it here.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:check_initialization_order=1:strict_init_order=1:intercept_tls_get_addr=0:log_path=$logs/asan"
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

# CI's subset: the test folders of every reader (core: rawlog, TUM lists and trajectories, depth
# PNGs, INI files; fuzz: all of them and maps, each input through the pipeline), the tracker,
# the optimizer, loop closing, the keyframe graph, the live pipeline's threads and checkpoints,
# and the viewer's windows opened and closed; only their targets are built (the whole tree under the
# sanitizers took 21 minutes of a CI run). `--all` builds and runs every test.
source scripts/lib/test-subsets.sh
ci_test_dirs=$sanitized_test_dirs
if [ $all = 1 ]; then
  config=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DSLAMDUNK_UBSAN=ON
    -DSLAMDUNK_TEST_DIRS="")
else
  config=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DSLAMDUNK_UBSAN=OFF
    -DSLAMDUNK_TEST_DIRS="$ci_test_dirs")
fi
cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSLAMDUNK_ASAN=ON \
  "${config[@]}" >"$logs/../configure.log" || { cat "$logs/../configure.log"; exit 1; }
# The rawlogs the tests share (tests/apps/prepare-test-data.sh): the Release tree's
# (scripts/test.sh runs the Release suite first), hard-linked, not copied. Rendering them again
# under the sanitizers took 26 minutes; the tools that make them run under the sanitizers in
# `--all`.
if [ -d build/test-data ] && [ ! -e "$build/test-data" ]; then
  mkdir -p "$build"
  cp -al build/test-data "$build/test-data" ||
    { rm -rf "$build/test-data"; cp -a build/test-data "$build/test-data"; }
fi
start=$SECONDS
targets=(--target "${sanitized_targets[@]}")
[ $all = 1 ] && targets=()
cmake --build "$build" -j"$(nproc)" "${targets[@]}" || { reports || true; exit 1; }
built=$SECONDS

subset=(-E "$(IFS='|'; echo "${sanitized_left_out[*]}")")
[ $all = 1 ] && subset=()
status=0
# -FS: the test data are the Release tree's, not made again here.
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -FS slamdunk_data "${subset[@]}" "$@" ||
  status=$?
echo "sanitize: build $((built - start)) s, tests $((SECONDS - built)) s"
reports || status=1
exit $status
