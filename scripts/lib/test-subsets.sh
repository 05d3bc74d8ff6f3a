# shellcheck shell=bash
# The test folders CI runs under the sanitizers (scripts/sanitize.sh), sourced by test.sh and
# sanitize.sh.
#   sanitized_test_dirs: CI's sanitizer subset (every reader, the tracker, the optimizer, loop
#     closing, the keyframe graph, the options, the live pipeline's threads and checkpoints, the
#     viewer's windows), built and run in ./build-asan.
#   sanitized_only_test_dirs: those of them whose every test runs there: CI's Release tree
#     (scripts/test.sh) does not build or run them a second time. The live pipeline's and the
#     viewer's folders stay in the Release tree: some of their tests run there only (real time,
#     whole sequences, the windows of both apps).
#   sanitized_targets: the subset's test binaries, the only targets built there.
#   sanitized_left_out: tests of those binaries the subset leaves out (ctest -E patterns).
# shellcheck disable=SC2034
sanitized_test_dirs="core;tracking;optimization;loop_closing;graph;grid_map;slam;fuzz;live;live-viewer"
sanitized_only_test_dirs="core;tracking;optimization;loop_closing;graph;grid_map;slam;fuzz"
sanitized_targets=(test_core test_tracking test_tracker_data test_local_optimizer
  test_loop_closing test_keyframe_graph test_slam_options fuzz-readers test_live_module
  test_viewer)
# Whole sequences through SLAM (minutes each under ASan, 10-45 times their Release time); their
# code runs in the tests that stay.
sanitized_left_out=(
  'LocalOptimizer\.TimingOnRealisticLocalProblems'
  # The whole synthetic loop through SLAM: checkpoints and resuming, the viewer's scene of a loop
  # closure. Under the sanitizers instead: checkpoints by time and after SIGKILL, the scene of a
  # short run (LiveMapSceneSmall).
  'Checkpoints\.EveryFewKeyframes' 'LiveMapScene\.ShowsTheMap'
  # Whole two-session and localization-only runs through LiveSlam (62 and 34 s under ASan, a
  # quarter of the subset's test time). Under the sanitizers instead: LiveSlam's threads,
  # callbacks and sensors on short runs (PushedFramesAreTrackedAndEveryPoseIsPublished, ...).
  'LiveSlam\.ASessionOutsideTheStartMapIsToldSoUntilItJoins'
  'LiveSlam\.LocalizationOnlyKeepsTheStartMapAndSaysWhereItEnds'
  # Under ASan its second viewer ends with exit code 1 instead of the expected one (first seen
  # in the run that added the viewer's windows to this subset; open, see the closing note of
  # issue 43). LiveViewer.ClosingWaitsForTheWindowThreadHoweverLongItIsBusy opens and closes a
  # window here.
  'LiveViewer\.TheLastViewerEndsTheWindowThreadHoweverLongItIsBusy'
  # The targets of these folders that the subset does not build.
  '_NOT_BUILT$'
)

# Prints a ctest -E pattern naming, in the tree $1, the tests of the sanitizer subset's
# binaries that the subset runs: tests a Release run may leave to it.
sanitized_tests_pattern() {
  # shellcheck disable=SC2016  # the program is Python's
  ctest --test-dir "$1" --show-only=json-v1 | python3 -c '
import json, os, re, sys
targets, left_out = set(sys.argv[1].split()), re.compile("|".join(sys.argv[2:]))
names = [t["name"] for t in json.load(sys.stdin)["tests"]
         if t.get("command") and os.path.basename(t["command"][0]) in targets
         and not left_out.search(t["name"])]
print("^(" + "|".join(re.escape(n) for n in sorted(names)) + ")$" if names else "^$_none")
' "${sanitized_targets[*]}" "${sanitized_left_out[@]}"
}
