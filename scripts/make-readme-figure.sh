#!/usr/bin/env bash
# Regenerates the README's pictures from SlamDunk on the 7-Scenes sequence of the shared data
# folder: docs/7scenes-map.png, its map rendered offscreen (dense cloud, trajectory, keyframes),
# and docs/7scenes-grid.png, that picture beside the occupancy grid made from the same map
# (--gridmap; ImageMagick's convert puts them side by side).
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
  --save-map "$work/7scenes.map" --map-images --gridmap "$work/7scenes-grid"
build/bin/slamdunk-render "$work/7scenes.map" docs/7scenes-map.png --width 800 --height 500 \
  --trajectory "$work/trajectory.txt" --scene "$work/7scenes.3Dscene"
# The map without its empty margins, and the grid with a grid cell (5 cm) as 4 x 4 pixels, at
# the same height side by side.
convert docs/7scenes-map.png -fuzz 3% -trim +repage -bordercolor "#1e1e23" -border 10 \
  -resize x460 "$work/map-trimmed.png"
convert "$work/7scenes-grid.png" -filter point -resize 400% -bordercolor white -border 12 \
  -resize x460 "$work/grid-large.png"
convert "$work/map-trimmed.png" "$work/grid-large.png" +append docs/7scenes-grid.png
ls -l docs/7scenes-map.png docs/7scenes-grid.png
