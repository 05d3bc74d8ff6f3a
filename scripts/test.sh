#!/usr/bin/env bash
# The test suite CI runs (.ci/run, with SLAMDUNK_REQUIRE_DATA=1): installs the dependencies,
# builds ./build (Release), runs the suite with ctest, then a subset under AddressSanitizer
# (scripts/sanitize.sh, ./build-asan). The unit tests of the readers, the tracker, the optimizer,
# the keyframe graph and the options, and the fuzzers' fixed inputs, run there only
# (scripts/lib/test-subsets.sh), as do the live pipeline's and the viewer's tests that subset
# runs. Within 25 minutes on 2 cores; the long runs it leaves out are
# scripts/test-long.sh's.
# Real recordings are taken from ../shared/data (override with SLAMDUNK_DATA_DIR). Where they,
# a tool or an X server are missing, tests skip with a message, or fail under
# SLAMDUNK_REQUIRE_DATA=1.
#   scripts/test.sh [CTEST_ARGS...]       (e.g. -R SlamdunkLive: both runs take the arguments)
#   SLAMDUNK_SKIP_SANITIZERS=1 scripts/test.sh   (every test in Release, none under the
#                                                 sanitizers: a developer's quick run)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/test-subsets.sh
start=$SECONDS
# Software OpenGL (Mesa's llvmpipe) renders on one thread per process: ctest already runs as
# many tests as there are cores, and its own threads only added switching. Same images.
export LP_NUM_THREADS=${LP_NUM_THREADS:-1}
# The folders whose every test runs under the sanitizers below are built and run there only.
if [ "${SLAMDUNK_SKIP_SANITIZERS:-0}" = 1 ]; then
  SLAMDUNK_SKIP_TEST_DIRS="" bash scripts/build.sh
else
  SLAMDUNK_SKIP_TEST_DIRS="$sanitized_only_test_dirs" bash scripts/build.sh
fi
built=$SECONDS

# Left to scripts/test-long.sh (SLAMDUNK_LONG_TESTS=1): the 2.5-minute hand-held scans (2 GB of
# test data; CI runs their first 20 s, handheld_scan20s), the hand-held sequences' exact-depth
# twins (CI tracks the Kinect-like ones, which have the same colour camera and noisier depth,
# with the readout calibrated and learned from nothing), and the list below. The flag also keeps
# the camera of HostileTracking.CameraStandingStillAddsNothing still for three minutes (CI: one).
long_runs=(
  'Synthetic/HandHeld\.EveryFrameTrackedWithoutJumps/scan_'
  'SlamdunkRawlog\.HandHeldScanLearnsItsCamerasReadout$'
  'Synthetic/HandHeld\.EveryFrameTrackedWithoutJumps/.*_exact'
  'Synthetic/HandHeldLearningTiming\.EveryFrameTrackedWithoutJumps/.*_exact'
  # The paper's 3D-3D cost on the whole of 7-Scenes, with and without optimization (CI checks
  # that cost on the synthetic loop, SyntheticLoopScaleAwareEdgeWeightsImproveTheOptimization).
  'SlamdunkRawlog\.SevenScenesWithThePapersCost$'
  # slamdunk-rawlog's optimizer thread on the whole of 7-Scenes (CI: on the synthetic loop, and
  # on 7-Scenes through the live replay, whose optimizer always runs beside tracking).
  'SlamdunkRawlogThreads\.OptimizerThreadKeepsTheAccuracyBoundsOnSevenScenes$'
  # The optimizer's time on realistic local problems: a benchmark's figures, printed (its one
  # bound, a map error under 5 cm, is loose; the other LocalOptimizer tests assert accuracy).
  'LocalOptimizer\.TimingOnRealisticLocalProblems$'
  # The drifting office tour's loop closed by place recognition (CI: the same tour with a bare
  # corridor, ATourWithABareCorridorIsTrackedAndClosed), and its occupancy grid through Kinect
  # depth and a loop-corrected map (CI: the same office with exact depth, tour_twins).
  'SlamdunkRawlogLoops\.PlaceRecognitionClosesTheDriftingOfficeTour$'
  'Office/SlamdunkRawlogGridMap\.TheOfficesGridMatchesItsGeometry/tour_drift '
)
[ "${SLAMDUNK_LONG_TESTS:-0}" = 1 ] && long_runs=()
# The live pipeline's and the viewer's tests that the sanitizer subset runs too run there only.
[ "${SLAMDUNK_SKIP_SANITIZERS:-0}" = 1 ] || long_runs+=("$(sanitized_tests_pattern build)")
subset=()
[ ${#long_runs[@]} -gt 0 ] && subset=(-E "$(IFS='|'; echo "${long_runs[*]}")")
ctest --test-dir build --output-on-failure -j"$(nproc)" "${subset[@]}" "$@"
tested=$SECONDS
echo "test.sh: Release build $((built - start)) s, suite $((tested - built)) s"
if [ "${SLAMDUNK_SKIP_SANITIZERS:-0}" = 1 ]; then
  echo "test.sh: sanitizer suite skipped (SLAMDUNK_SKIP_SANITIZERS=1)"
else
  bash scripts/sanitize.sh "$@"
fi
echo "test.sh: $((SECONDS - start)) s in all"
