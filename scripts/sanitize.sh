#!/usr/bin/env bash
# The test suite under AddressSanitizer (with LeakSanitizer) and UndefinedBehaviorSanitizer:
# builds ./build-asan (RelWithDebInfo, SLAMDUNK_ASAN + SLAMDUNK_UBSAN) and runs ctest there.
# Any sanitizer report fails the run, also one from a tool a test runs (slamdunk-rawlog,
# tum2rawlog, ...), which a test expecting that tool to fail could otherwise mistake for the
# failure it expects: ASan/LSan reports go to build-asan/sanitizer-logs/ and are printed at the
# end; UBSan (combined with ASan, GCC's runtime ignores log_path) prints to stderr and aborts,
# and tests/common's runCommand() fails the test on any report in a tool's output.
#   scripts/sanitize.sh                   CI's subset: every test but the long runs named below
#   scripts/sanitize.sh --all             every test (about an hour more on 2 cores)
#   scripts/sanitize.sh -R SlamdunkLive   extra arguments go to ctest
# Leaks inside third-party libraries are suppressed in scripts/sanitizers/lsan.supp (each entry
# says why); a report in this project's code is a bug to fix, not to suppress.
# RelWithDebInfo (-O2): compiling took about as long as at -O1 here (one Eigen-heavy file: 51 s
# vs 47 s with both sanitizers), and the suite is mostly optimized Eigen code, far slower at -O1.
# Debug information -g1 (line tables, no variables): reports still name file and line of every
# frame, inlined ones too; the Eigen-heavy BundleAdjuster.cpp compiled in 62 s instead of 79 s and
# its object is a quarter of the size, which the many test executables' links feel too.
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
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DSLAMDUNK_ASAN=ON -DSLAMDUNK_UBSAN=ON
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

# CI's subset. Left out: runs of whole sequences through SLAM, the renderer or the converter,
# and the real-time replays. Each takes 2-7 minutes under the sanitizers (10-45 times its
# Release time) and all of them together would put CI past its 90 minutes. Their code runs
# under the sanitizers in the tests that stay: SLAM with keyframes, loop closure and the
# optimizer on the synthetic loop, on fr1_desk_9f and on fr3_cabinet_58kf (wide baselines);
# live replay stopped by SIGINT/SIGTERM; maps saved, loaded, rendered and corrupted; every
# renderer effect; the converter on fr3_cabinet_58kf and on damaged folders; all unit tests
# and the fuzzers. `--all` runs these too.
long_runs=(
  'SlamdunkRawlog\.(SevenScenes|TumFr1Xyz|HandHeldScan|TwoRuns|SyntheticSweep|SyntheticLoop(Optimization|Scale|With|Lights))'
  'SlamdunkRawlogThreads\.' 'SlamdunkRawlogMaps\.Relocalizes' 'Synthetic/HandHeld\.'
  'SlamdunkLive\.(RealTime|DoubleSpeed)' 'test_dense_7scenes'
  'LocalOptimizer\.TimingOnRealisticLocalProblems' 'SlamDunkMapBuilder\.MatchesSlamSystem'
  'Tum2RawlogOnRealData\.ReadBackMatchesSource/7scenes' 'Tum2Rawlog\.SevenScenesOpensInRawlogEdit'
  'SyntheticRgbdTool\.Tour' 'SyntheticSequence\.TourFrames'
  # 5400 frames of a still camera, 630 and 800 frames round the loop through SLAM (27, 13 and
  # 15 s in Release); their code (tracking, relocalization) runs in the tests that stay.
  'HostileTracking\.'
  # The whole synthetic loop through SLAM (12-13 s in Release each): checkpoints and resuming,
  # and the viewer's scene of a loop closure. Under the sanitizers instead: checkpoints by time
  # and after SIGKILL, the scene of a short run (LiveMapSceneSmall).
  'Checkpoints\.EveryFewKeyframes' 'LiveMapScene\.ShowsTheMap'
)
subset=(-E "$(IFS='|'; echo "${long_runs[*]}")")
if [ "${1:-}" = --all ]; then
  subset=()
  shift
fi

status=0
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" "${subset[@]}" "$@" || status=$?
echo "sanitize: build $((built - start)) s, tests $((SECONDS - built)) s"
reports || status=1
exit $status
