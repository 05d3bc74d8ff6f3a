#!/usr/bin/env bash
# Does the live viewer slow tracking down? slamdunk-rawlog on 7-Scenes (1000 frames) with and
# without --gui, runs interleaved (with, without, with, ...) so that a machine shared with other
# work loads both alike; prints each run and the medians of fps (whole app) and tracking p95/max.
# The window is drawn on a virtual X server (Xvfb) with Mesa's software renderer.
#   scripts/benchmark-gui.sh [RUNS] [RAWLOG]    (default 5 runs each; build/test-data/7scenes.rawlog)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/summary.sh
source scripts/lib/xvfb.sh
runs=${1:-5}
rawlog=${2:-build/test-data/7scenes.rawlog}
app=build/bin/slamdunk-rawlog
start_gui_benchmark benchmark-gui "$app" "$rawlog"

printf "%-8s %4s %8s %8s %8s %8s\n" mode run fps p50_ms p95_ms max_ms
for i in $(seq "$runs"); do
  for mode in gui plain; do
    flags=()
    [ "$mode" = gui ] && flags=(--gui)
    "$app" "$rawlog" -t "$out/t.txt" --json -q "${flags[@]}" >"$out/$mode-$i.json"
    printf "%-8s %4d %8s %8s %8s %8s\n" "$mode" "$i" "$(field fps "$out/$mode-$i.json")" \
      "$(field ms_tracking_median "$out/$mode-$i.json")" \
      "$(field ms_tracking_p95 "$out/$mode-$i.json")" "$(field ms_tracking_max "$out/$mode-$i.json")"
  done
done
echo "medians of $runs runs:"
for mode in gui plain; do
  printf "%-8s fps %s, tracking p50 %s ms, p95 %s ms, max %s ms\n" "$mode" \
    "$(for f in "$out/$mode"-*.json; do value fps "$f"; done | median)" \
    "$(for f in "$out/$mode"-*.json; do value ms_tracking_median "$f"; done | median)" \
    "$(for f in "$out/$mode"-*.json; do value ms_tracking_p95 "$f"; done | median)" \
    "$(for f in "$out/$mode"-*.json; do value ms_tracking_max "$f"; done | median)"
done
