#!/usr/bin/env bash
# Does the local map follow the space covered or the time spent? Runs slamdunk-rawlog (default
# INI) RUNS times on 7-Scenes seq-1000f and on the synthetic "dwell" sequence (a minute turning
# in one spot, hand-held camera, Kinect-like depth) and prints, per block of frames, tracking
# p50 / p95 / max, the pool's size and the keyframes made (medians of the runs), then each
# run's summary figures.
#   scripts/benchmark-local-map.sh [RUNS]     (default 3; needs a built tree: scripts/build.sh)
#   SEQUENCES="dwell" scripts/benchmark-local-map.sh   (one of them)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
source scripts/lib/benchmark.sh

prepare_recording "$bin" "$data/7scenes/seq-1000f" config-ini/cameras/7scenes.ini \
  "$work/7scenes.rawlog" || true
[ -f "$work/dwell_kinect.rawlog" ] ||
  "$bin/synthetic-rgbd" "$work/dwell_exact.rawlog" --kinect-twin "$work/dwell_kinect.rawlog" \
    --trajectory dwell --hand-held --supersampling 1 --external-images --jpeg-quality 95 -q \
    >/dev/null

for name in ${SEQUENCES:-7scenes dwell}; do
  rawlog=$work/$name.rawlog block=200
  ini=config-ini/slamdunk-default.ini
  if [ "$name" = dwell ]; then
    # The hand-held camera's depth comes 5 ms after colour: part of its calibration.
    rawlog=$work/dwell_kinect.rawlog block=300 ini=$work/dwell.ini
    sed "s/^depth_time_offset_ms .*/depth_time_offset_ms = 5/" config-ini/slamdunk-default.ini \
      >"$ini"
  fi
  [ -f "$rawlog" ] || continue
  logs=()
  echo "## $name ($runs runs)"
  for ((r = 1; r <= runs; r++)); do
    out=$work/local-map-$name-$r
    "$bin/slamdunk-rawlog" "$rawlog" --config "$ini" --trajectory "$out.txt" \
      --gt "${rawlog%.rawlog}_groundtruth.txt" --frame-log "$out.csv" --json -q >"$out.json"
    logs+=("$out.csv")
  done
  python3 scripts/frame-log-blocks.py "$block" "${logs[@]}"
  echo
  for ((r = 1; r <= runs; r++)); do
    j=$work/local-map-$name-$r.json
    echo "run $r: keyframes $(field keyframes "$j"), optimizations $(field optimizations "$j")" \
      "(median $(field ms_optimization_median "$j") ms, $(field optimizer_share "$j") of the run)," \
      "ATE $(field ate_rmse_m "$j") m," \
      "$(field fps "$j") frames/s, peak RSS $(field peak_rss_mib "$j") MiB," \
      "$(field map_kib_per_keyframe "$j") KiB per keyframe"
  done
  echo
done
