#!/usr/bin/env bash
# Regenerates docs/7scenes-map.png, the README's picture: SlamDunk on the 7-Scenes sequence of
# the shared data folder, its map rendered offscreen (dense cloud, trajectory, keyframes).
#   scripts/make-readme-figure.sh      (needs a built tree: scripts/build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${SLAMDUNK_DATA_DIR:-$(pwd)/../shared/data}
work=build/figure
mkdir -p "$work" docs
source scripts/lib/rawlog.sh
prepare_recording build/bin "$data/7scenes/seq-1000f" config-ini/cameras/7scenes.ini \
  "$work/7scenes.rawlog"
build/bin/slamdunk-rawlog "$work/7scenes.rawlog" -t "$work/trajectory.txt" -q \
  --save-map "$work/7scenes.map" --map-images
build/bin/slamdunk-render "$work/7scenes.map" docs/7scenes-map.png --width 800 --height 500 \
  --trajectory "$work/trajectory.txt" --scene "$work/7scenes.3Dscene"
ls -l docs/7scenes-map.png
