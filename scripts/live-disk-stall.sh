#!/usr/bin/env bash
# Live replay under disk pressure: slamdunk-live replays 7-Scenes in real time while another process
# writes and flushes 100 MB every half second on the same file system, and the images' access
# times are set back before each run so that reading them updates them (as in a fresh clone,
# whose images were just written). On ext4 such a read, or a write, can wait for the journal
# commit a flush forces; a thread that reads or writes files can stop for hundreds of ms.
# Prints one line per run: frames dropped, grab-to-pose latency p50 / p95 / max, the longest
# gap between frames from the source and the longest wait for the tracker, ATE.
#   scripts/live-disk-stall.sh [RUNS] [RAWLOG]   (default 3; build/test-data/7scenes.rawlog)
#   BEFORE=/other/build/bin scripts/live-disk-stall.sh   alternates runs of another build's
#                                                         slamdunk-live with this one's
#   SPEED=2 scripts/live-disk-stall.sh      replays at twice the recorded rate
#   PRESSURE=0 scripts/live-disk-stall.sh   no writing process (the same runs on a quiet disk)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
rawlog=$(realpath "${2:-build/test-data/7scenes.rawlog}")
gt=${rawlog%.rawlog}_groundtruth.txt
images=${rawlog%.rawlog}_Images
[ -x build/bin/slamdunk-live ] || { echo "live-disk-stall: build first (scripts/build.sh)" >&2; exit 1; }
[ -f "$rawlog" ] || { echo "live-disk-stall: $rawlog missing (ctest -R prepare_test_data)" >&2; exit 1; }
builds=(build/bin)
[ -n "${BEFORE:-}" ] && builds=("$BEFORE" build/bin)
out=$(mktemp -d)
pressure=$(dirname "$rawlog")/disk-pressure.tmp
printf '[slamdunk-live]\nsource = REPLAY\n[REPLAY]\ndriver = replay\nrawlog = %s\n' "$rawlog" \
  >"$out/live.ini"
writer=""
if [ "${PRESSURE:-1}" != 0 ]; then
  (while :; do
    dd if=/dev/zero of="$pressure" bs=1M count=100 conv=fsync status=none
    sleep 0.5
  done) &
  writer=$!
fi
trap '[ -n "$writer" ] && { kill $writer; wait $writer; } 2>/dev/null; rm -rf "$out" "$pressure"' EXIT

keys=(frames_dropped latency_ms_p50 latency_ms_p95 latency_ms_max source_gap_ms_max
  queue_wait_ms_max ate_rmse_m)
value() { sed -n "s/.*\"$1\": \([0-9.]*\).*/\1/p" "$2" | head -1; }
printf "%-24s %3s" build run
printf " %s" "${keys[@]}"
echo
for i in $(seq "$runs"); do
  for bin in "${builds[@]}"; do
    # Older than any image's modification time: with relatime, the next read updates it.
    [ -d "$images" ] && find "$images" -type f -exec touch -a -d 2000-01-01 {} +
    "$bin/slamdunk-live" --config "$out/live.ini" --trajectory "$out/t.txt" --json -q \
      --speed "${SPEED:-1}" --gt "$gt" >"$out/run.json"
    printf "%-24s %3d" "$bin" "$i"
    for k in "${keys[@]}"; do printf " %s" "$(value "$k" "$out/run.json")"; done
    echo
  done
done
