#!/usr/bin/env bash
# What each accuracy option does on each sequence: the default INI, then the default with one
# option changed at a time (and all of them changed: the earlier defaults), ATE RMSE per
# sequence as a Markdown table. Runs are deterministic: one run per cell.
#   scripts/accuracy-ablation.sh            (needs the rawlogs of scripts/benchmark.sh, in
#                                           build/benchmark: run that first)
#   SEQUENCES="7scenes fr1_xyz_400f" scripts/accuracy-ablation.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/bin
work=build/benchmark
[ -d "$work" ] || { echo "accuracy-ablation: $work not found: run scripts/benchmark.sh first" >&2; exit 1; }
sequences=${SEQUENCES:-7scenes fr1_xyz_400f synthetic_loop synthetic_loop_kinect handheld_rotations_exact handheld_rotations_kinect handheld_shake_exact handheld_shake_kinect fr1_desk_9f}

# name|key=value ...: the configurations, each against the default INI
configs=(
  "default|"
  "paper's 3D-3D cost (residual_form = edge)|residual_form=edge"
  "keypoint noise not learned|estimate_keypoint_noise=false"
  "rolling shutter not learned|estimate_rolling_shutter=false"
  "frame velocity not estimated (estimate_frame_velocity = false)|estimate_frame_velocity=false"
  "window follows position only (window_shift_angle = 0)|window_shift_angle=0"
  "textured_cell_features = 6|textured_cell_features=6"
  "all of edge, not learned, no velocity, angle 0|residual_form=edge estimate_keypoint_noise=false estimate_rolling_shutter=false estimate_frame_velocity=false window_shift_angle=0"
)

field() { { grep -o "\"$1\": *[-0-9.eE+]*" || true; } | head -1 | sed 's/.*: *//'; }

present=()
for s in $sequences; do [ -f "$work/$s.rawlog" ] && present+=("$s"); done
header="| configuration |"
rule="|---|"
for s in "${present[@]}"; do header+=" $s |"; rule+="---|"; done
echo "ATE RMSE m (keyframes); hand-held sequences with depth_time_offset_ms = 5 (their calibration)"
echo
echo "$header"
echo "$rule"
for c in "${configs[@]}"; do
  name=${c%%|*}
  edits=${c#*|}
  row="| $name |"
  for s in "${present[@]}"; do
    ini=$work/ablation.ini
    cp config-ini/slamdunk-default.ini "$ini"
    [[ $s == handheld_* ]] && sed -i "s/^depth_time_offset_ms .*/depth_time_offset_ms = 5/" "$ini"
    for kv in $edits; do
      key=${kv%%=*}
      grep -q "^$key " "$ini" || { echo "accuracy-ablation: no key '$key' in the default INI" >&2; exit 1; }
      sed -i "s/^$key .*/$key = ${kv#*=}/" "$ini"
    done
    out=$("$bin/slamdunk-rawlog" "$work/$s.rawlog" --config "$ini" -t "$work/ablation.txt" --json -q \
          --gt "$work/${s}_groundtruth.txt")
    row+=" $(echo "$out" | field ate_rmse_m) ($(echo "$out" | field keyframes)) |"
  done
  echo "$row"
done
