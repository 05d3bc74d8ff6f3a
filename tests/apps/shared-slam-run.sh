#!/usr/bin/env bash
# One SLAM run that several tests check, made once per suite (a setup test of the CTest fixture
# shared_runs, tests/apps/CMakeLists.txt): slamdunk-rawlog on a prepared rawlog with the given
# arguments. Its outputs go to OUT_DIR: trajectory.txt (and trajectory_keyframes.txt), run.map,
# output.txt (the program's --json summary and messages), and whatever the arguments add. The
# tests read them through sharedRun(NAME). A rawlog that was not prepared (its recording missing)
# makes no run: the tests on it skip, or fail under SLAMDUNK_REQUIRE_DATA=1, by themselves.
#   Usage: shared-slam-run.sh SLAMDUNK_RAWLOG RAWLOG OUT_DIR [ARGS...]
set -euo pipefail
tool=$1 rawlog=$2 out=$3
shift 3
rm -rf "$out"
if [ ! -f "$rawlog" ]; then
  echo "shared-slam-run: $rawlog was not prepared: no run in $out"
  exit 0
fi
mkdir -p "$out"
gt=${rawlog%.rawlog}_groundtruth.txt
gt_args=()
[ -f "$gt" ] && gt_args=(--gt "$gt")
status=0
"$tool" "$rawlog" -t "$out/trajectory.txt" --json -q --save-map "$out/run.map" \
  "${gt_args[@]}" "$@" >"$out/output.part" 2>&1 || status=$?
cat "$out/output.part"
if [ $status != 0 ]; then
  echo "shared-slam-run: slamdunk-rawlog exited with $status" >&2
  rm -rf "$out"
  exit 1
fi
# Last: a run that did not end leaves no output.txt, which the tests take for no run.
mv "$out/output.part" "$out/output.txt"
