# The test folders CI runs under the sanitizers (scripts/sanitize.sh), sourced by test.sh and
# sanitize.sh.
#   sanitized_test_dirs: CI's sanitizer subset (every reader, the tracker, the optimizer, loop
#     closing, the keyframe graph, the options, the live pipeline's threads and checkpoints, the
#     viewer's windows), built and run in ./build-asan.
#   sanitized_only_test_dirs: those of them whose every test runs there: CI's Release tree
#     (scripts/test.sh) does not build or run them a second time. The live pipeline's and the
#     viewer's folders stay in the Release suite: some of their tests run there only (real time,
#     whole sequences, the windows of both apps).
# shellcheck disable=SC2034
sanitized_test_dirs="core;tracking;optimization;loop_closing;graph;grid_map;slam;fuzz;live;live-viewer"
sanitized_only_test_dirs="core;tracking;optimization;loop_closing;graph;grid_map;slam;fuzz"
