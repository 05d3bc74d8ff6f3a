#!/usr/bin/env bash
# The main job on a built-in default, no downloads: installs dependencies, builds, renders the
# project's synthetic loop sequence (exact ground truth), runs SlamDunk on it and prints ATE.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
out=build/demo
mkdir -p "$out"
if [ ! -f "$out/synthetic_loop.rawlog" ]; then
  build/bin/synthetic-rgbd "$out/synthetic_loop.rawlog" --trajectory loop
fi
build/bin/slamdunk-rawlog "$out/synthetic_loop.rawlog" \
  --config config-ini/slamdunk-default.ini \
  --trajectory "$out/trajectory.txt" \
  --gt "$out/synthetic_loop_groundtruth.txt"
echo
echo "Trajectory: $out/trajectory.txt (keyframes: $out/trajectory_keyframes.txt)"
build/bin/evaluate-trajectory "$out/synthetic_loop_groundtruth.txt" "$out/trajectory.txt"
