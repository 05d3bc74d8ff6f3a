#!/usr/bin/env bash
# Accuracy and speed figures for the README's results table. Every number in the table comes
# from this script: it converts the shared recordings (if present), runs slamdunk-rawlog RUNS
# times per configuration and prints medians as a Markdown table.
#   scripts/benchmark.sh [RUNS]      (default 3; needs a built tree: scripts/build.sh)
#   FEATURES="SURF64 ORB" SEQUENCES="7scenes" scripts/benchmark.sh   (a subset of the rows)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
data=${SLAMDUNK_DATA_DIR:-$(pwd)/../shared/data}
bin=build/bin
work=build/benchmark
mkdir -p "$work"

prepare() {  # prepare NAME SEQ CAMERA
  [ -f "$work/$1.rawlog" ] && return 0
  [ -d "$data/$2" ] || { echo "skipping $1: $data/$2 not found" >&2; return 1; }
  "$bin/tum2rawlog" "$data/$2" "$work/$1.rawlog" --camera "config-ini/cameras/$3" \
    --external-images -q >/dev/null
}
[ -f "$work/synthetic_loop.rawlog" ] || "$bin/synthetic-rgbd" "$work/synthetic_loop.rawlog" -q >/dev/null
[ -f "$work/synthetic_loop_kinect.rawlog" ] ||
  "$bin/synthetic-rgbd" "$work/synthetic_loop_kinect.rawlog" --kinect-depth -q >/dev/null
prepare 7scenes 7scenes/seq-1000f 7scenes.ini || true
prepare fr1_desk_9f tum/fr1_desk_9f tum-fr1.ini || true
prepare fr3_cabinet_58kf tum/fr3_cabinet_58kf tum-fr3.ini || true

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
field() { { grep -o "\"$1\": *[-0-9.eE+]*" || true; } | head -1 | sed 's/.*: *//'; }

# run NAME FEATURE EXTRA_SLAM_ARGS...: prints one table row
run() {
  local name=$1 feature=$2; shift 2
  local rawlog=$work/$name.rawlog
  [ -f "$rawlog" ] || return 0
  local ini=$work/bench-$feature.ini
  sed "s/^type .*/type = $feature/" config-ini/slamdunk-default.ini > "$ini"
  local fps=() track=() ate=() ateNoOpt=() tracked="" frames="" kf="" opt="" optMax=""
  for ((i = 0; i < runs; i++)); do
    out=$("$bin/slamdunk-rawlog" "$rawlog" --config "$ini" -t "$work/traj.txt" --json -q \
          --gt "$work/${name}_groundtruth.txt" "$@")
    fps+=("$(echo "$out" | field fps)")
    track+=("$(echo "$out" | field ms_tracking_median)")
    ate+=("$(echo "$out" | field ate_rmse_m)")
    tracked=$(echo "$out" | field tracked); frames=$(echo "$out" | field frames)
    kf=$(echo "$out" | field keyframes); opt=$(echo "$out" | field ms_optimization_median)
    optMax=$(echo "$out" | field ms_optimization_max)
  done
  out=$("$bin/slamdunk-rawlog" "$rawlog" --config "$ini" -t "$work/traj.txt" --json -q \
        --gt "$work/${name}_groundtruth.txt" --no-optimization "$@")
  local ateNo; ateNo=$(echo "$out" | field ate_rmse_m)
  printf "| %s | %s | %s/%s | %s | %s | %s | %s | %s | %s/%s |\n" "$name" "$feature" \
    "$tracked" "$frames" "$kf" "$(printf '%s\n' "${ate[@]}" | median)" "${ateNo:-n/a}" \
    "$(printf '%s\n' "${fps[@]}" | median)" "$(printf '%s\n' "${track[@]}" | median)" \
    "$opt" "$optMax"
}

echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'); runs per row: $runs (medians)"
echo
echo "| sequence | features | tracked | keyframes | ATE RMSE m (local opt.) | ATE RMSE m (tracking only) | app FPS | tracking ms/frame (median) | local opt. ms median/max |"
echo "|---|---|---|---|---|---|---|---|---|"
features=${FEATURES:-SURF64 SURF128 SIFT ORB}
sequences=${SEQUENCES:-7scenes synthetic_loop synthetic_loop_kinect fr1_desk_9f fr3_cabinet_58kf}
for s in $sequences; do
  if [ "$s" = 7scenes ]; then
    for f in $features; do run 7scenes "$f"; done
  else
    run "$s" SURF64
  fi
done
