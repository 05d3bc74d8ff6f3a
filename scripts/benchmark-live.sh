#!/usr/bin/env bash
# What the live viewer and the checkpoints cost a live session: slamdunk-live replaying 7-Scenes
# in real time (1000 frames, 30 Hz) three ways, interleaved run by run so that a machine shared
# with other work loads them alike: default (checkpoints on: every 10 keyframes or 30 s),
# --gui (viewer on a virtual X server, Xvfb), and checkpoints off. Prints each run and medians:
# frames dropped, tracking ms p50/p95/max, grab-to-pose latency p95, checkpoints and their ms.
#   scripts/benchmark-live.sh [RUNS] [RAWLOG]   (default 3; build/test-data/7scenes.rawlog)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/summary.sh
source scripts/lib/xvfb.sh
runs=${1:-3}
rawlog=$(realpath "${2:-build/test-data/7scenes.rawlog}")
app=build/bin/slamdunk-live
start_gui_benchmark benchmark-live "$app" "$rawlog"
printf '[slamdunk-live]\nsource = REPLAY\n[REPLAY]\ndriver = replay\nrawlog = %s\n' "$rawlog" \
  >"$out/default.ini"
printf '[slamdunk-live]\nsource = REPLAY\ncheckpoint_every_keyframes = 0\ncheckpoint_every_seconds = 0\n[REPLAY]\ndriver = replay\nrawlog = %s\n' \
  "$rawlog" >"$out/nocheckpoints.ini"

keys=(frames_dropped ms_tracking_median ms_tracking_p95 ms_tracking_max latency_ms_p95 checkpoints
  checkpoint_ms_median checkpoint_ms_max checkpoint_snapshot_ms_max)
printf "%-14s %3s" mode run
printf " %s" "${keys[@]}"
echo
for i in $(seq "$runs"); do
  for mode in default gui nocheckpoints; do
    ini=$out/default.ini flags=()
    [ "$mode" = nocheckpoints ] && ini=$out/nocheckpoints.ini
    [ "$mode" = gui ] && flags=(--gui)
    "$app" --config "$ini" --trajectory "$out/t.txt" --json -q "${flags[@]}" >"$out/$mode-$i.json"
    printf "%-14s %3d" "$mode" "$i"
    for k in "${keys[@]}"; do printf " %s" "$(field "$k" "$out/$mode-$i.json")"; done
    echo
  done
done
echo "medians of $runs runs:"
for mode in default gui nocheckpoints; do
  printf "%-14s" "$mode"
  for k in "${keys[@]}"; do
    printf " %s=%s" "$k" "$(for f in "$out/$mode"-*.json; do value "$k" "$f"; done | median)"
  done
  echo
done
