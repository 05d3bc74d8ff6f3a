#!/usr/bin/env bash
# What each accuracy option does on each sequence: the default INI, then the default with one
# option changed at a time (and all of them changed: the earlier defaults), ATE RMSE per
# sequence as a Markdown table. Runs are deterministic: one run per cell.
#   scripts/accuracy-ablation.sh            (needs the rawlogs of scripts/benchmark.sh, in
#                                           build/benchmark: run that first)
#   SEQUENCES="7scenes fr1_xyz_400f" scripts/accuracy-ablation.sh
#   ROWS="default|velocity prior" scripts/accuracy-ablation.sh   (only the rows whose name matches)
#   SEEDS="42 43 44 45 46 47 48" scripts/accuracy-ablation.sh   (each cell: the median ATE over
#                                           these RANSAC seeds [lowest-highest] and the keyframes'
#                                           range: a real sequence's ATE moves by a few percent
#                                           with the seed alone)
#   TREE_SEEDS="1 2 3 4 5" scripts/accuracy-ablation.sh   (each cell over these KD-tree seeds too,
#                                           with SEEDS or RANSAC seed 42: the tree moves ATE more
#                                           than RANSAC's seed; docs/experiments.md)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/bin
work=build/benchmark
[ -d "$work" ] || { echo "accuracy-ablation: $work not found: run scripts/benchmark.sh first" >&2; exit 1; }
sequences=${SEQUENCES:-7scenes fr1_xyz_400f synthetic_loop synthetic_loop_kinect handheld_rotations_exact handheld_rotations_kinect handheld_shake_exact handheld_shake_kinect fr1_desk_9f}

# name|key=value ...: the configurations, each against the default INI
configs=(
  "default|"
  "tracking only (local_optimization = false)|local_optimization=false"
  "paper's 3D-3D cost (residual_form = edge)|residual_form=edge"
  "keypoint noise not learned|estimate_keypoint_noise=false"
  "rolling shutter not learned|estimate_rolling_shutter=false"
  "frame velocity not estimated (estimate_frame_velocity = false)|estimate_frame_velocity=false"
  "window follows position only (window_shift_angle = 0)|window_shift_angle=0"
  "textured_cell_features = 6|textured_cell_features=6"
  "velocity prior always at its widest (velocity_prior_adaptive = false)|velocity_prior_adaptive=false"
  "fewer keyframes (keyframe_overlap = 0.7)|keyframe_overlap=0.7"
  "more keyframes (keyframe_overlap = 0.9)|keyframe_overlap=0.9"
  "keyframes culled (keyframe_cull_share = 0.6)|keyframe_cull_share=0.6"
  "keyframes culled (keyframe_cull_share = 0.7)|keyframe_cull_share=0.7"
  "keyframes culled (keyframe_cull_share = 0.65)|keyframe_cull_share=0.65"
  "a keyframe wherever the overlap is low (keyframe_covered_view = 0, the paper)|keyframe_covered_view=0"
  "FLANN's KD-tree (pool_index = flann, kdtree_checks = 64; the default before 2026-12-07)|pool_index=flann kdtree_checks=64"
  "own k-d tree for every pool part (pool_brute_force_below = 0)|pool_brute_force_below=0"
  "more ratio-test neighbours (knn_neighbours = 8)|knn_neighbours=8"
  "no pool budget (pool_budget = 0)|pool_budget=0"
  "pool budget 12,000 (pool_budget = 12000)|pool_budget=12000"
  "pool budget 8,000 (pool_budget = 8000)|pool_budget=8000"
  "all of edge, not learned, no velocity, angle 0|residual_form=edge estimate_keypoint_noise=false estimate_rolling_shutter=false estimate_frame_velocity=false window_shift_angle=0"
)

source scripts/lib/summary.sh
run() {  # run <sequence> <ini>: the app's JSON summary
  "$bin/slamdunk-rawlog" "$work/$1.rawlog" --config "$2" -t "$work/ablation.txt" --json -q \
    --gt "$work/${1}_groundtruth.txt"
}

present=()
for s in $sequences; do [ -f "$work/$s.rawlog" ] && present+=("$s"); done
header="| configuration |"
rule="|---|"
for s in "${present[@]}"; do header+=" $s |"; rule+="---|"; done
if [ -n "${TREE_SEEDS:-}" ]; then
  SEEDS=${SEEDS:-42}
  echo "ATE RMSE m, median [lowest-highest] over KD-tree seeds $TREE_SEEDS and RANSAC seeds $SEEDS; hand-held sequences with depth_time_offset_ms = 5 (their calibration)"
elif [ -n "${SEEDS:-}" ]; then
  echo "ATE RMSE m, median [lowest-highest] over RANSAC seeds $SEEDS; hand-held sequences with depth_time_offset_ms = 5 (their calibration)"
else
  echo "ATE RMSE m (keyframes); hand-held sequences with depth_time_offset_ms = 5 (their calibration)"
fi
echo
echo "$header"
echo "$rule"
for c in "${configs[@]}"; do
  name=${c%%|*}
  edits=${c#*|}
  [ -n "${ROWS:-}" ] && ! echo "$name" | grep -qE "$ROWS" && continue
  row="| $name |"
  for s in "${present[@]}"; do
    ini=$work/ablation.ini
    cp config-ini/slamdunk-advanced.ini "$ini"
    [[ $s == handheld_* ]] && sed -i "s/^depth_time_offset_ms .*/depth_time_offset_ms = 5/" "$ini"
    for kv in $edits; do
      key=${kv%%=*}
      grep -q "^$key " "$ini" || { echo "accuracy-ablation: no key '$key' in the advanced INI" >&2; exit 1; }
      sed -i "s/^$key .*/$key = ${kv#*=}/" "$ini"
    done
    if [ -z "${SEEDS:-}" ]; then
      out=$(run "$s" "$ini")
      row+=" $(echo "$out" | field ate_rmse_m) ($(echo "$out" | field keyframes)) |"
      continue
    fi
    ates=() keyframes=()
    for tree in ${TREE_SEEDS:-keep}; do
      [ "$tree" = keep ] || sed -i "s/^kdtree_seed .*/kdtree_seed = $tree/" "$ini"
      for seed in $SEEDS; do
        sed -i "s/^ransac_seed .*/ransac_seed = $seed/" "$ini"
        out=$(run "$s" "$ini")
        ates+=("$(echo "$out" | field ate_rmse_m)")
        keyframes+=("$(echo "$out" | field keyframes)")
      done
    done
    row+=" $(printf '%s\n' "${ates[@]}" | sort -g | awk '{a[NR]=$1} END {m = NR % 2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2; printf "%.4f [%.4f-%.4f]", m, a[1], a[NR]}')"
    row+=" ($(printf '%s\n' "${keyframes[@]}" | sort -n | sed -n '1p;$p' | paste -sd-) keyframes) |"
  done
  echo "$row"
done
