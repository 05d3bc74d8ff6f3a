#!/usr/bin/env bash
# Loop closing beyond the active window (issue 46): the office tour (55 m round four rooms)
# through a Kinect-like camera whose stated focal length is 3 % off, so that the odometry drifts
# by decimetres, run with local optimization alone ([loop_closing] enabled = false) and with
# place recognition and global correction (the default), RUNS times each, offline and with the
# back end on its thread (optimizer_thread = true, as live), then replayed live at 1x. Prints
# per run and as medians: ATE, the error at the loop's return (scripts/loop-return-error.py),
# loops found, look-up ms (median / max per keyframe), correction ms, the optimizer's share,
# tracking p95 over the run and over the 30 frames before the correction reached the tracker.
#   scripts/benchmark-loops.sh [RUNS]          (default 3; needs a built tree: scripts/build.sh)
#   SEQUENCES="tour_drift" scripts/benchmark-loops.sh   (the long runs' test sequence only)
#   PARTS="sessions" scripts/benchmark-loops.sh   (some of: drift live sessions aliasing; default all)
# tour_drift: 1100 frames (three times walking pace, the long runs' test); tour_drift_full: 3300
# frames at walking pace (about a minute to render, once); tour_drift_handheld: tour_drift with the
# hand-held camera's effects too (motion blur, rolling shutter, auto exposure, depth 5 ms late;
# several minutes to render, once); tour_drift_handheld_bare: tour_drift_handheld with the
# corridor from room B to room C painted almost plain (--bare-corridor: 7 m with few features).
# Then two sessions of one walk (exact depth): the first maps part of the tour, the second starts
# where that map does not reach and walks into it; prints whether it joined and how far the
# joined map's keyframes are from the ground truth in the first session's frame
# (scripts/map-frame-error.py). tour_session: CI's pair (three times walking pace);
# tour_session_full: the same stretches at walking pace.
# Last, aliasing: the tour through the office whose room C is a copy of room A (--twin-rooms),
# with the drift guard and without it (max_drift_share = 100), and two sessions there (the
# corridor from D into A, then the corridor from B into C): loops and joins accepted and refused.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
source scripts/lib/benchmark.sh

render() {  # render NAME FRAMES [SYNTHETIC-RGBD ARGS]
  local name=$1 frames=$2
  shift 2
  [ -f "$work/$name.rawlog" ] ||
    "$bin/synthetic-rgbd" "$work/$name.rawlog" --trajectory tour --frames "$frames" "$@" \
      --kinect-depth --stated-focal-error 3 --external-images --jpeg-quality 95 \
      --supersampling 1 -q >/dev/null
}
render tour_drift 1100
render tour_drift_full 3300
render tour_drift_handheld 1100 --hand-held
render tour_drift_handheld_bare 1100 --hand-held --bare-corridor
session() {  # session NAME FRAMES SKIP FIRST: a stretch of the tour, exact depth
  [ -f "$work/$1.rawlog" ] ||
    "$bin/synthetic-rgbd" "$work/$1.rawlog" --trajectory tour --frames "$2" --skip-frames "$3" \
      --first-frames "$4" --external-images --jpeg-quality 95 --supersampling 1 -q >/dev/null
}
session tour_session1 1100 250 250
session tour_session2 1100 100 300
session tour_session_full1 3300 750 750
session tour_session_full2 3300 300 900
twins() {  # twins NAME [SYNTHETIC-RGBD ARGS]: the office with twin rooms
  local name=$1
  shift
  [ -f "$work/$name.rawlog" ] ||
    "$bin/synthetic-rgbd" "$work/$name.rawlog" --trajectory tour --frames 1100 --twin-rooms "$@" \
      --external-images --jpeg-quality 95 --supersampling 1 -q >/dev/null
}
twins tour_twins
twins tour_twins_session1 --skip-frames 900
twins tour_twins_session2 --skip-frames 350 --first-frames 200
printf '[loop_closing]\nenabled = false\n' >"$work/loops-local.ini"
printf '[slam]\noptimizer_thread = true\n' >"$work/loops-thread.ini"
printf '[loop_closing]\nenabled = false\n[slam]\noptimizer_thread = true\n' \
  >"$work/loops-local-thread.ini"

# p95 of ms_total over all frames, and over the frames around each loop correction: from 30
# frames before the first frame that reports it (loop_corrected) to 10 after. With a second
# frame log (a run with loop closing), the frames around its corrections: the same frames of a
# run without loop closing, for comparison (the return itself costs more: old keyframes enter
# the pool).
p95s() {
  python3 - "$1" "${2:-$1}" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
reference = list(csv.DictReader(open(sys.argv[2])))
ms = [float(r["ms_total"]) for r in rows if r["ms_total"]]
def p95(v):
    v = sorted(v)
    if not v: return float("nan")
    k = 0.95 * (len(v) - 1); lo = int(k); hi = min(lo + 1, len(v) - 1)
    return v[lo] + (k - lo) * (v[hi] - v[lo])
corrected = [int(r["index"]) for r in reference if r.get("loop_corrected") == "1"]
around = {i for c in corrected for i in range(c - 30, c + 11)}
during = [float(r["ms_total"]) for r in rows if r["ms_total"] and int(r["index"]) in around]
print("%.1f %.1f" % (p95(ms), p95(during)))
PY
}

keys=(ate_rmse_m place_loops place_lookup_ms_p50 place_lookup_ms_max loop_correction_ms_max
  optimizer_share)
parts=${PARTS:-drift live sessions aliasing}
part() { [[ " $parts " == *" $1 "* ]]; }

for name in ${SEQUENCES:-tour_drift tour_drift_full tour_drift_handheld tour_drift_handheld_bare}; do
  part drift || continue
  rawlog=$work/$name.rawlog gt=$work/${name}_groundtruth.txt
  echo "## $name ($runs runs)"
  printf "%-13s %3s %s return_m return_deg p95_ms p95_around_correction_ms\n" mode run \
    "${keys[*]}"
  for mode in global local global-thread local-thread; do
    ini=config-ini/slamdunk-default.ini
    case $mode in
      local) ini=$work/loops-local.ini ;;
      global-thread) ini=$work/loops-thread.ini ;;
      local-thread) ini=$work/loops-local-thread.ini ;;
    esac
    for ((r = 1; r <= runs; r++)); do
      out=$work/loops-$name-$mode-$r
      "$bin/slamdunk-rawlog" "$rawlog" --config "$ini" --trajectory "$out.txt" --gt "$gt" \
        --frame-log "$out.csv" --json -q >"$out.json"
      read -r _ _ ret _ deg _ < <(python3 scripts/loop-return-error.py "$out.txt" "$gt" | tr -d ',')
      printf "%-13s %3d" "$mode" "$r"
      for k in "${keys[@]}"; do printf " %s" "$(field "$k" "$out.json")"; done
      with=$out.csv  # the frames around the corrections of the run with loop closing
      [[ $mode == local* ]] && with=$work/loops-$name-global${mode#local}-$r.csv
      printf " %s %s %s\n" "$ret" "$deg" "$(p95s "$out.csv" "$with")"
      echo "$ret $deg $(p95s "$out.csv" "$with")" >"$out.extra"
    done
    printf "%-13s med" "$mode"
    for k in "${keys[@]}"; do
      printf " %s" "$(for f in "$work/loops-$name-$mode"-[0-9]*.json; do field "$k" "$f"; done | median)"
    done
    for col in 1 2 3 4; do
      printf " %s" "$(for f in "$work/loops-$name-$mode"-[0-9]*.extra; do cut -d' ' -f$col "$f"; done |
        grep -v nan | median)"
    done
    echo
  done
  echo
done

# Live at 1x (slamdunk-live replaying CI's tour, back end on its thread): frames dropped, loops;
# tracking p95 over the run and around the correction, then the same frames without loop
# closing.
part live || runs_live=0
rawlog=$(realpath "$work/tour_drift.rawlog")
printf '[slamdunk-live]\nsource = REPLAY\n[REPLAY]\ndriver = replay\nrawlog = %s\n' "$rawlog" \
  >"$work/loops-live.ini"
printf '[pipeline.loop_closing]\nenabled = false\n' | cat "$work/loops-live.ini" - \
  >"$work/loops-live-local.ini"
part live && echo "## tour_drift live at 1x"
for ((r = 1; r <= ${runs_live:-runs}; r++)); do
  out=$work/loops-live-$r
  "$bin/slamdunk-live" --config "$work/loops-live.ini" --trajectory "$out.txt" \
    --gt "${rawlog%.rawlog}_groundtruth.txt" --frame-log "$out.csv" --json -q >"$out.json"
  "$bin/slamdunk-live" --config "$work/loops-live-local.ini" --trajectory "$out-local.txt" \
    --frame-log "$out-local.csv" --json -q >"$out-local.json"
  echo "run $r: frames_dropped $(field frames_dropped "$out.json"), place_loops" \
    "$(field place_loops "$out.json"), ate_rmse_m $(field ate_rmse_m "$out.json"), tracking" \
    "p95 over the run / around the correction $(p95s "$out.csv") ms, the same frames without" \
    "loop closing $(p95s "$out-local.csv" "$out.csv") ms," \
    "$(python3 scripts/loop-return-error.py "$out.txt" "${rawlog%.rawlog}_groundtruth.txt")"
done

# Two sessions: the second from the first's saved map, offline, RUNS times.
for pair in tour_session tour_session_full; do
  part sessions || continue
  echo "## $pair: a second session joins the first's map ($runs runs)"
  first=$work/${pair}1 second=$work/${pair}2
  "$bin/slamdunk-rawlog" "$first.rawlog" --trajectory "$work/$pair-first.txt" -q \
    --save-map "$work/$pair-first.map" >/dev/null
  for ((r = 1; r <= runs; r++)); do
    out=$work/loops-$pair-$r
    "$bin/slamdunk-rawlog" "$second.rawlog" --trajectory "$out.txt" --keyframes "$out-kf.txt" \
      --load-map "$work/$pair-first.map" --frame-log "$out.csv" --json -q >"$out.json"
    echo "run $r: components_started $(field components_started "$out.json"), joined" \
      "$(field components_joined "$out.json"), correction ms $(field loop_correction_ms_max "$out.json")," \
      "tracking p95 / during the join $(p95s "$out.csv") ms;" \
      "$(python3 scripts/map-frame-error.py "$out-kf.txt" "${first}_groundtruth.txt" \
        "${second}_groundtruth.txt")"
  done
done

# Aliasing: the twin rooms, one session and two.
if part aliasing; then
  printf '[loop_closing]\nmax_drift_share = 100\n' >"$work/loops-unguarded.ini"
  echo "## tour_twins: room C a copy of room A"
  for mode in guarded unguarded; do
    ini=config-ini/slamdunk-default.ini
    [ $mode = unguarded ] && ini=$work/loops-unguarded.ini
    out=$work/loops-twins-$mode
    "$bin/slamdunk-rawlog" "$work/tour_twins.rawlog" --config "$ini" --trajectory "$out.txt" \
      --gt "$work/tour_twins_groundtruth.txt" --json -q >"$out.json"
    echo "$mode: place_loops $(field place_loops "$out.json"), candidates verified" \
      "$(field place_candidates_verified "$out.json"), refused" \
      "$(field place_candidates_refused "$out.json"), ate_rmse_m $(field ate_rmse_m "$out.json")"
  done
  echo "## tour_twins sessions: the second walks into A's copy"
  "$bin/slamdunk-rawlog" "$work/tour_twins_session1.rawlog" --trajectory "$work/twins-first.txt" \
    -q --save-map "$work/twins-first.map" >/dev/null
  out=$work/loops-twins-sessions
  "$bin/slamdunk-rawlog" "$work/tour_twins_session2.rawlog" --trajectory "$out.txt" --json -q \
    --load-map "$work/twins-first.map" >"$out.json"
  echo "components_started $(field components_started "$out.json"), joined" \
    "$(field components_joined "$out.json"), joins refused" \
    "$(field component_joins_refused "$out.json"), relocalizations" \
    "$(field relocalizations "$out.json")"
fi
