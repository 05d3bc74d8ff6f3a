#!/usr/bin/env bash
# Scale benchmark (issue 10, not run in CI): SlamDunk along the 55 m office "tour" with
# Kinect-like depth, with a keyframe policy that spawns more than 300 keyframes
# (keyframe_overlap = 0.95; the default gives about 80 there). Prints tracking ms p50/p95/max
# per block of 100 keyframes (the per-frame cost must follow the window, not the map), the
# peak RSS, and memory per keyframe with and without keyframe images, two ways: the keyframe
# graph's data counted directly (KeyframeGraph::memory(), the `map_kib_*` figures of
# `slamdunk-rawlog --json`), and the peak RSS of the whole run minus that of its first half,
# over the keyframes between them (which also moves with what the allocator keeps).
#   scripts/benchmark-scale.sh            (renders the tour once: about 4 minutes)
#   TOUR=/path/tour_kinect.rawlog scripts/benchmark-scale.sh   (an existing rendering)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/bin
work=build/benchmark/scale
mkdir -p "$work"
tour=${TOUR:-$work/tour_kinect.rawlog}
if [ ! -f "$tour" ]; then
  echo "rendering the tour into $tour ..." >&2
  "$bin/synthetic-rgbd" "$tour" --trajectory tour --kinect-depth --external-images -q >/dev/null
fi
gt=${tour%.rawlog}_groundtruth.txt
sed 's/^keyframe_overlap .*/keyframe_overlap = 0.95/' config-ini/slamdunk-default.ini > "$work/scale.ini"
# The default INI lists only the key parameters: the images' key goes into its section.
sed '/^\[tracker\]/a keep_keyframe_images = true' "$work/scale.ini" > "$work/scale-images.ini"
grep -q '^keep_keyframe_images = true' "$work/scale-images.ini"
frames=$(grep -vc '^#' "$gt")

source scripts/lib/summary.sh
run() {  # run INI MAX_FRAMES [EXTRA...]: JSON summary
  local ini=$1 max=$2; shift 2
  "$bin/slamdunk-rawlog" "$tour" --config "$ini" -t "$work/traj.txt" --json -q \
    --max-frames "$max" "$@"
}

full=$(run "$work/scale.ini" "$frames" --gt "$gt" --frame-log "$work/frames.csv")
echo "tour: $frames frames, $(echo "$full" | field keyframes) keyframes, ATE $(echo "$full" | field ate_rmse_m) m, $(echo "$full" | field fps) frames/s, peak RSS $(echo "$full" | field peak_rss_mib) MiB"
echo "map data per keyframe, counted: $(echo "$full" | field map_kib_per_keyframe) KiB (in all: features $(echo "$full" | field map_kib_features), small depth $(echo "$full" | field map_kib_depth_small), edges $(echo "$full" | field map_kib_edges) KiB)"
echo
echo "| keyframes | frames | tracking ms p50 | p95 | max |"
echo "|---|---|---|---|---|"
# The frame log's columns, found by name.
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
  { if ($col["new_keyframe"] == 1) kf++; print int(kf / 100), $col["ms_total"] }' "$work/frames.csv" |
  sort -k1,1n -k2,2g |
  awk '{ v[$1, ++n[$1]] = $2 }
       END { for (b in n) {
               m = n[b]; p50 = v[b, int((m + 1) / 2)]; p95 = v[b, int(0.95 * m + 0.999)]
               printf "| %d-%d | %d | %.1f | %.1f | %.1f |\n", b * 100, b * 100 + 99, m, p50, p95, v[b, m] } }' |
  sort -t- -k1,1n

half=$((frames / 2))
for ini in scale scale-images; do
  a=$(run "$work/$ini.ini" "$half"); b=$(run "$work/$ini.ini" "$frames")
  [ "$ini" = scale-images ] &&
    echo "map data per keyframe with images, counted: $(echo "$b" | field map_kib_per_keyframe_with_images) KiB"
  ka=$(echo "$a" | field keyframes); kb=$(echo "$b" | field keyframes)
  ra=$(echo "$a" | field peak_rss_mib); rb=$(echo "$b" | field peak_rss_mib)
  awk -v ka="$ka" -v kb="$kb" -v ra="$ra" -v rb="$rb" -v what="$ini" 'BEGIN {
    printf "%s: peak RSS %.1f MiB at %d keyframes, %.1f MiB at %d: %.0f KB per keyframe\n",
      (what == "scale" ? "without keyframe images" : "with keyframe images"), ra, ka, rb, kb,
      (rb - ra) * 1024 / (kb - ka) }'
done
