#!/usr/bin/env bash
# Does the live viewer slow tracking down? slamdunk-rawlog on 7-Scenes (1000 frames) with and
# without --gui, runs interleaved (with, without, with, ...) so that a machine shared with other
# work loads both alike; prints each run and the medians of fps (whole app) and tracking p95/max.
# The window is drawn on a virtual X server (Xvfb) with Mesa's software renderer.
#   scripts/benchmark-gui.sh [RUNS] [RAWLOG]    (default 5 runs each; build/test-data/7scenes.rawlog)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
rawlog=${2:-build/test-data/7scenes.rawlog}
app=build/bin/slamdunk-rawlog
[ -x "$app" ] || { echo "benchmark-gui: build first (scripts/build.sh)" >&2; exit 1; }
[ -f "$rawlog" ] || { echo "benchmark-gui: $rawlog missing (ctest -R prepare_test_data)" >&2; exit 1; }
out=$(mktemp -d)
source scripts/lib/xvfb.sh
start_xvfb benchmark-gui

value() { sed -n "s/.*\"$1\": \([0-9.]*\).*/\1/p" "$2" | head -1; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
printf "%-8s %4s %8s %8s %8s %8s\n" mode run fps p50_ms p95_ms max_ms
for i in $(seq "$runs"); do
  for mode in gui plain; do
    flags=()
    [ "$mode" = gui ] && flags=(--gui)
    "$app" "$rawlog" -t "$out/t.txt" --json -q "${flags[@]}" >"$out/$mode-$i.json"
    printf "%-8s %4d %8s %8s %8s %8s\n" "$mode" "$i" "$(value fps "$out/$mode-$i.json")" \
      "$(value ms_tracking_median "$out/$mode-$i.json")" \
      "$(value ms_tracking_p95 "$out/$mode-$i.json")" "$(value ms_tracking_max "$out/$mode-$i.json")"
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
