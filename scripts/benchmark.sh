#!/usr/bin/env bash
# Accuracy and speed figures for the README's results table. Every number in the table comes
# from this script: it converts the shared recordings (if present), runs slamdunk-rawlog RUNS
# times per configuration and prints medians as a Markdown table.
#   scripts/benchmark.sh [RUNS]      (default 3; needs a built tree: scripts/build.sh)
#   FEATURES="SURF64 ORB" SEQUENCES="7scenes" scripts/benchmark.sh   (a subset of the rows)
#   NO_LIVE=1 scripts/benchmark.sh   (without the live-replay rows: they take 50 s per run)
#   BUSY_LOOPS=2 scripts/benchmark.sh   (a shared machine: N busy loops run beside every row)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
source scripts/lib/benchmark.sh
prepare() {  # prepare NAME SEQ CAMERA
  prepare_recording "$bin" "$data/$2" "config-ini/cameras/$3" "$work/$1.rawlog"
}
# Exact and Kinect-like depth from one render (--kinect-twin: the twin is byte for byte what
# --kinect-depth alone renders).
[ -f "$work/synthetic_loop.rawlog" ] && [ -f "$work/synthetic_loop_kinect.rawlog" ] ||
  "$bin/synthetic-rgbd" "$work/synthetic_loop.rawlog" \
    --kinect-twin "$work/synthetic_loop_kinect.rawlog" -q >/dev/null
# Hand-held motion through a hand-held camera (blur, 20 ms rolling shutter, auto exposure, depth
# 5 ms after colour): as tests/apps/prepare-test-data.sh renders them. The scan (2.5 minutes)
# only with HANDHELD_SCAN=1: rendering it takes long.
handheld=(rotations shake)
[ -n "${HANDHELD_SCAN:-}" ] && handheld+=(scan)
for t in "${handheld[@]}"; do
  name=handheld_$t
  [ -f "$work/${name}_exact.rawlog" ] && [ -f "$work/${name}_kinect.rawlog" ] ||
    "$bin/synthetic-rgbd" "$work/${name}_exact.rawlog" --kinect-twin "$work/${name}_kinect.rawlog" \
      --trajectory "$t" --hand-held --supersampling 1 --external-images -q >/dev/null
done
prepare 7scenes 7scenes/seq-1000f 7scenes.ini || true
prepare fr1_xyz_400f tum/fr1_xyz_400f tum-fr1.ini || true
prepare fr1_desk_9f tum/fr1_desk_9f tum-fr1.ini || true
prepare fr3_cabinet_58kf tum/fr3_cabinet_58kf tum-fr3.ini || true

# Other work on the machine: busy loops at the same priority, stopped when the script ends.
busy=()
trap '[ ${#busy[@]} -eq 0 ] || kill "${busy[@]}" 2>/dev/null' EXIT
for ((i = 0; i < ${BUSY_LOOPS:-0}; i++)); do
  (while :; do :; done) &
  busy+=($!)
done

# run NAME FEATURE EXTRA_SLAM_ARGS...: prints one table row
run() {
  local name=$1 feature=$2; shift 2
  local rawlog=$work/$name.rawlog
  [ -f "$rawlog" ] || return 0
  local ini=$work/bench-$feature.ini
  sed "s/^type .*/type = $feature/" config-ini/slamdunk-default.ini > "$ini"
  # The hand-held camera's depth is captured 5 ms after colour: part of its calibration (the
  # rolling shutter is learned).
  [[ $name == handheld_* ]] && sed -i "s/^depth_time_offset_ms .*/depth_time_offset_ms = 5/" "$ini"
  local fps=() p50=() p95=() p99=() pmax=() prep=() prepMax=() ate=()
  local tracked="" frames="" kf="" opt="" optMax=""
  for ((i = 0; i < runs; i++)); do
    out=$("$bin/slamdunk-rawlog" "$rawlog" --config "$ini" -t "$work/traj.txt" --json -q \
          --gt "$work/${name}_groundtruth.txt" "$@")
    fps+=("$(echo "$out" | field fps)")
    p50+=("$(echo "$out" | field ms_tracking_median)")
    p95+=("$(echo "$out" | field ms_tracking_p95)")
    p99+=("$(echo "$out" | field ms_tracking_p99)")
    pmax+=("$(echo "$out" | field ms_tracking_max)")
    prep+=("$(echo "$out" | field ms_pool_preparation_median)")
    prepMax+=("$(echo "$out" | field ms_pool_preparation_max)")
    ate+=("$(echo "$out" | field ate_rmse_m)")
    tracked=$(echo "$out" | field tracked); frames=$(echo "$out" | field frames)
    kf=$(echo "$out" | field keyframes); opt=$(echo "$out" | field ms_optimization_median)
    optMax=$(echo "$out" | field ms_optimization_max)
  done
  # Accuracy beyond ATE, from the last run (runs are deterministic): RPE over one frame period
  # (its median and its largest: outlier frames) and over one second.
  # A sequence with too few tracked frames to align (fr3_cabinet_58kf) has no such row.
  local gt=$work/${name}_groundtruth.txt perFrame perSecond
  perFrame=$("$bin/evaluate-trajectory" "$gt" "$work/traj.txt" --json --rpe-delta 0.0333 2>/dev/null) || true
  perSecond=$("$bin/evaluate-trajectory" "$gt" "$work/traj.txt" --json 2>/dev/null) || true
  [ -n "$perFrame" ] && [ -n "$perSecond" ] && accuracy+=("$(printf "| %s | %s | %s | %.4f / %.4f | %.3f / %.3f | %.4f / %.3f | %s |" \
    "$name" "$feature" "$(echo "$out" | field ate_rmse_m)" \
    "$(echo "$perFrame" | field rpe_trans_median_m_per_s)" \
    "$(echo "$perFrame" | field rpe_trans_max_m_per_s)" \
    "$(echo "$perFrame" | field rpe_rot_median_deg_per_s)" \
    "$(echo "$perFrame" | field rpe_rot_max_deg_per_s)" \
    "$(echo "$perSecond" | field rpe_trans_rmse_m_per_s)" \
    "$(echo "$perSecond" | field rpe_rot_rmse_deg_per_s)" \
    "$(echo "$out" | field camera_rolling_shutter_ms)")")
  out=$("$bin/slamdunk-rawlog" "$rawlog" --config "$ini" -t "$work/traj.txt" --json -q \
        --gt "$work/${name}_groundtruth.txt" --no-optimization "$@")
  local ateNo; ateNo=$(echo "$out" | field ate_rmse_m)
  m() { printf '%s\n' "$@" | median; }
  local ateMed; ateMed=$(m "${ate[@]}"); [ -n "$ateMed" ] || ateMed=n/a
  printf "| %s | %s | %s/%s | %s | %s | %s | %s | %s / %s / %s / %s | %s / %s | %s/%s |\n" \
    "$name" "$feature" "$tracked" "$frames" "$kf" "$ateMed" "${ateNo:-n/a}" \
    "$(m "${fps[@]}")" "$(m "${p50[@]}")" "$(m "${p95[@]}")" "$(m "${p99[@]}")" \
    "$(m "${pmax[@]}")" "$(m "${prep[@]}")" "$(m "${prepMax[@]}")" "$opt" "$optMax"
}

# live NAME SPEED: one row of live replay (slamdunk-live paced by the timestamps)
live() {
  local name=$1 speed=$2 rawlog=$work/$1.rawlog
  [ -f "$rawlog" ] || return 0
  printf '[slamdunk-live]\nsource = REPLAY\n[REPLAY]\ndriver = replay\nrawlog = %s\n' \
    "$(realpath "$rawlog")" > "$work/live.ini"
  local dropped=() p50=() p95=() pmax=() ate=() received=""
  for ((i = 0; i < runs; i++)); do
    out=$("$bin/slamdunk-live" --config "$work/live.ini" --trajectory "$work/live.txt" --json -q \
          --speed "$speed" --gt "$work/${name}_groundtruth.txt")
    received=$(echo "$out" | field frames_received)
    dropped+=("$(echo "$out" | field frames_dropped)")
    p50+=("$(echo "$out" | field latency_ms_p50)")
    p95+=("$(echo "$out" | field latency_ms_p95)")
    pmax+=("$(echo "$out" | field latency_ms_max)")
    ate+=("$(echo "$out" | field ate_rmse_m)")
  done
  m() { printf '%s\n' "$@" | median; }
  printf "| %s | %sx | %s | %s | %s / %s / %s | %s |\n" "$name" "$speed" "$received" \
    "$(m "${dropped[@]}")" "$(m "${p50[@]}")" "$(m "${p95[@]}")" "$(m "${pmax[@]}")" \
    "$(m "${ate[@]}")"
}

echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'); runs per row: $runs (medians)${BUSY_LOOPS:+; $BUSY_LOOPS busy loops beside}"
echo
echo "| sequence | features | tracked | keyframes | ATE RMSE m (local opt.) | ATE RMSE m (tracking only) | app FPS | tracking ms p50 / p95 / p99 / max | pool preparation ms median / max | local opt. ms median/max |"
echo "|---|---|---|---|---|---|---|---|---|---|"
features=${FEATURES:-SURF64 SURF128 SIFT ORB}
handheldRows=""
for t in "${handheld[@]}"; do handheldRows+=" handheld_${t}_exact handheld_${t}_kinect"; done
sequences=${SEQUENCES:-7scenes fr1_xyz_400f synthetic_loop synthetic_loop_kinect$handheldRows fr1_desk_9f fr3_cabinet_58kf}
accuracy=()
for s in $sequences; do
  if [ "$s" = 7scenes ]; then
    for f in $features; do run 7scenes "$f"; done
  else
    run "$s" SURF64
  fi
done
echo
echo "| sequence | features | ATE RMSE m | RPE per frame m median / max | deg median / max | RPE per second RMSE m / deg | rolling shutter learned ms |"
echo "|---|---|---|---|---|---|---|"
for row in "${accuracy[@]}"; do echo "$row"; done
if [ -z "${NO_LIVE:-}" ]; then
  echo
  echo "| live replay | speed | frames | dropped | latency grab to pose ms p50 / p95 / max | ATE RMSE m |"
  echo "|---|---|---|---|---|---|"
  for speed in 1 2; do live 7scenes "$speed"; done
fi
