#!/usr/bin/env bash
# Soak test (issue 13, not run in CI): the live pipeline on the synthetic loop replayed again and
# again in real time ([REPLAY] loops = 0: each lap's stamps follow the last, and the loop ends
# where it began, so this is a camera walking round the same room for as long as the test runs;
# after the first laps the map stops growing). Samples the app's resident memory (VmRSS from
# /proc/PID/status) every few seconds and takes each frame's latency from grab to pose from its
# frame log, then prints:
#   - the RSS slope after warm-up (least squares over the samples from one minute after the last
#     new keyframe, and from a tenth of the run at the earliest: memory settles for a minute or
#     so after the map stops growing, the last optimizations and pool windows), in MB per hour.
#     Every frame leaves records for the session (its pose relative to its keyframe for the
#     trajectory and the checkpoints, its timing, its latency: 144 + 144 + 48 + 8 B); they are
#     SessionLogs, whose entries beyond the newest chunk live in a temporary file, so they add
#     nothing that grows: the whole slope is what the session's memory does;
#   - frames, keyframes added, latency p50 / p95 / max per time block;
#   - whether memory is flat (the slope within +-SOAK_RSS_TOLERANCE MB/h, 5 by default) and latency
#     steady (every block's p95 after warm-up within 1.3 x the lowest + 2 ms), and the latency's
#     trend in ms per hour (a machine shared with other work makes block p95s jump).
#   scripts/soak.sh                 30 minutes, blocks of 5 minutes
#   scripts/soak.sh 5 1             5 minutes, blocks of 1 minute (a quick check)
#   SOAK_NICE=5 scripts/soak.sh     the app at lower priority (a shared machine)
#   SOAK_RAWLOG=x.rawlog scripts/soak.sh   another recording (it should end where it begins)
#   SOAK_CHECKPOINTS=0 scripts/soak.sh      checkpoints off
#   SOAK_LOCALIZE_IN=MAP scripts/soak.sh   localization only in a saved map (--load-map MAP
#                                           --localize): no keyframe, the map as it was loaded
#   SOAK_WORK=DIR scripts/soak.sh           outputs in DIR (default build/soak)
#   scripts/soak.sh --analyse [BLOCK]      the figures of the last run again (build/soak)
# Outputs stay in build/soak/: frames.csv (per frame; latency.csv, the columns read here), rss.csv
# (per sample), summary.json, log.
set -euo pipefail
cd "$(dirname "$0")/.."
analyse_only=0
if [ "${1:-}" = --analyse ]; then analyse_only=1; shift; set -- 0 "$@"; fi
minutes=${1:-30}
block=${2:-5}
interval=${SOAK_SAMPLE_SECONDS:-5}
tolerance=${SOAK_RSS_TOLERANCE:-5}
bin=build/bin
work=${SOAK_WORK:-build/soak}
mkdir -p "$work"
checkpoints=${SOAK_CHECKPOINTS:-1}
run() {  # the soak itself: the app replaying, RSS sampled, stopped by SIGINT
  for tool in slamdunk-live synthetic-rgbd; do
    [ -x "$bin/$tool" ] || { echo "soak: $bin/$tool not built (run scripts/build.sh)" >&2; exit 1; }
  done

  rawlog=${SOAK_RAWLOG:-}
  if [ -z "$rawlog" ]; then
    rawlog=build/test-data/synthetic_loop.rawlog  # made by the test suite, if it ran
    if [ ! -f "$rawlog" ]; then
      rawlog=$work/loop.rawlog
      [ -f "$rawlog" ] || "$bin/synthetic-rgbd" "$rawlog" --trajectory loop -q >/dev/null
    fi
  fi
  rawlog=$(realpath "$rawlog")
  checkpointKeys=""
  [ "$checkpoints" = 0 ] && checkpointKeys=$'checkpoint_every_keyframes = 0\ncheckpoint_every_seconds = 0'
  cat > "$work/live.ini" <<EOF
[slamdunk-live]
source = REPLAY
$checkpointKeys
[REPLAY]
driver = replay
rawlog = $rawlog
loops  = 0
EOF

  rm -f "$work/frames.csv" "$work/latency.csv" "$work/summary.json"
  echo "seconds,rss_kib" > "$work/rss.csv"
  echo "soak: $minutes minutes of $rawlog replayed in a loop, RSS every $interval s ..." >&2
  localize=()
  [ -n "${SOAK_LOCALIZE_IN:-}" ] && localize=(--load-map "$(realpath "$SOAK_LOCALIZE_IN")" --localize)
  nice -n "${SOAK_NICE:-0}" "$bin/slamdunk-live" --config "$work/live.ini" "${localize[@]}" \
    --trajectory "$work/trajectory.txt" --frame-log "$work/frames.csv" --json \
    > "$work/summary.json" 2> "$work/log" &
  pid=$!
  trap 'kill -INT $pid 2>/dev/null || true' EXIT
  start=$(date +%s.%N)
  end=$(awk -v s="$start" -v m="$minutes" 'BEGIN { printf "%.3f", s + 60 * m }')
  while kill -0 "$pid" 2>/dev/null; do
    now=$(date +%s.%N)
    awk -v n="$now" -v e="$end" 'BEGIN { exit !(n >= e) }' && break
    rss=$(awk '/^VmRSS:/ { print $2 }' "/proc/$pid/status" 2>/dev/null || true)
    [ -n "$rss" ] && awk -v n="$now" -v s="$start" -v r="$rss" \
      'BEGIN { printf "%.1f,%d\n", n - s, r }' >> "$work/rss.csv"
    sleep "$interval"
  done
  kill -INT "$pid" 2>/dev/null || { echo "soak: the app ended early:" >&2; tail "$work/log" >&2; exit 1; }
  wait "$pid" || { echo "soak: the app failed:" >&2; tail "$work/log" >&2; exit 1; }
  trap - EXIT
}
[ "$analyse_only" = 1 ] || run

source scripts/lib/summary.sh
summary() { field "$1" "$work/summary.json"; }
echo "received $(summary frames_received), processed $(summary frames_processed), dropped $(summary frames_dropped), lost $(summary lost), keyframes $(summary keyframes), map $(summary map_kib) KiB, optimizations $(summary optimizations), loop closures $(summary loop_closures)"

# The frame log's columns used here, found by name: 1 grab_s, 2 latency_ms, 3 new_keyframe.
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
  { print $col["grab_s"] "," $col["latency_ms"] "," $col["new_keyframe"] }' "$work/frames.csv" \
  > "$work/latency.csv"
lastkf=$(awk -F, '$3 == 1 { t = $1 } END { printf "%.0f", t + 0 }' "$work/latency.csv")
read -r fps duration < <(awk -F, '{ n++; t = $1 } END { printf "%.2f %.0f\n", (t > 0 ? n / t : 0), t }' "$work/latency.csv")
warmup=$(awk -v k="$lastkf" -v d="$duration" 'BEGIN { w = k + 60; if (w < d / 10) w = d / 10; printf "%.0f", w }')
echo "warm-up: the last keyframe was added at ${lastkf} s, memory measured from ${warmup} s; $fps frames/s processed over $duration s"

# RSS: least-squares slope over the samples after warm-up.
awk -F, -v w="$warmup" -v tol="$tolerance" '
  NR > 1 && $1 >= w { n++; sx += $1; sy += $2; sxx += $1 * $1; sxy += $1 * $2
                      if (n == 1) first = $2; last = $2 }
  END {
    if (n < 3) { print "RSS: fewer than 3 samples after warm-up: run longer"; exit }
    slope = (n * sxy - sx * sy) / (n * sxx - sx * sx)           # KiB per second
    mbh = slope * 3600 * 1024 / 1e6
    printf "RSS after warm-up: %.1f -> %.1f MiB over %d samples; slope %+.1f MB/h: %s\n",
      first / 1024, last / 1024, n, mbh,
      (mbh <= tol && mbh >= -tol) ? "FLAT" : "NOT FLAT (beyond +-" tol " MB/h)"
  }' "$work/rss.csv"

# Latency per block of `block` minutes of grab time.
echo
echo "| minutes | frames | keyframes added | latency ms p50 | p95 | max |"
echo "|---|---|---|---|---|---|"
awk -F, -v b="$block" '{ print int($1 / (60 * b)), $2, $3 }' "$work/latency.csv" |
  sort -k1,1n -k2,2g |
  awk -v b="$block" -v w="$warmup" '
    { k = $1; v[k, ++n[k]] = $2; kf[k] += $3; if (!(k in seen)) { seen[k] = 1; order[++blocks] = k } }
    END {
      lo = 1e18; hi = 0
      for (i = 1; i <= blocks; i++) {
        k = order[i]; m = n[k]
        p95 = v[k, int(0.95 * m + 0.999)]
        printf "| %g-%g | %d | %d | %.1f | %.1f | %.1f |\n", k * b, (k + 1) * b, m, kf[k], v[k, int((m + 1) / 2)], p95, v[k, m]
        # Blocks wholly after warm-up, and full ones (the last may be a few seconds long).
        if (k * b * 60 >= w && m >= 0.5 * 30 * 60 * b) { if (p95 < lo) lo = p95; if (p95 > hi) hi = p95; used++ }
      }
      if (used == 0) { print "\nlatency: no full block after warm-up: run longer"; exit }
      printf "\nlatency p95 over %d full blocks after warm-up: %.1f to %.1f ms: %s\n", used, lo, hi,
        (hi <= 1.3 * lo + 2) ? "STEADY" : "NOT STEADY (the highest beyond 1.3 x the lowest + 2 ms)"
    }'

# Creep: the least-squares slope of every frame's latency after warm-up (a busy machine makes
# block p95s jump; a trend shows here).
awk -F, -v w="$warmup" '$1 >= w { n++; sx += $1; sy += $2; sxx += $1 * $1; sxy += $1 * $2 }
  END { if (n > 2) printf "latency trend after warm-up: %+.1f ms per hour (least squares over %d frames)\n",
          3600 * (n * sxy - sx * sy) / (n * sxx - sx * sx), n }' "$work/latency.csv"
