#!/usr/bin/env bash
# Regenerates docs/live-viewer.png, the README's picture of the live viewer: slamdunk-rawlog
# --gui on the 7-Scenes sequence (first 600 frames) in a virtual X server (Xvfb), the window
# captured with ImageMagick's import once the run has ended (--gui-wait keeps it open), then
# closed with its q key (xdotool).
#   scripts/make-viewer-screenshot.sh [FRAMES]   (needs a built tree and the shared data folder)
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-600}
data=${SLAMDUNK_DATA_DIR:-$(pwd)/../shared/data}
work=build/figure
mkdir -p "$work" docs
for tool in Xvfb xwininfo import xdotool; do
  command -v "$tool" >/dev/null ||
    { echo "make-viewer-screenshot: $tool missing (scripts/install-deps.sh)" >&2; exit 1; }
done
source scripts/lib/rawlog.sh
prepare_recording build/bin "$data/7scenes/seq-1000f" config-ini/cameras/7scenes.ini \
  "$work/7scenes.rawlog"

Xvfb :"$((100 + RANDOM % 800))" -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp -noreset \
  3>"$work/display" 2>"$work/xvfb.log" &
xvfb=$!
app=
trap 'kill $app $xvfb 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { echo "make-viewer-screenshot: Xvfb did not start" >&2; exit 1; }
export DISPLAY=:$(cat "$work/display")

build/bin/slamdunk-rawlog "$work/7scenes.rawlog" -t "$work/viewer-trajectory.txt" \
  --max-frames "$frames" --gui --gui-wait 2>"$work/viewer.log" >/dev/null &
app=$!
for _ in $(seq 1200); do
  grep -qs "close the viewer window" "$work/viewer.log" && break
  kill -0 "$app" 2>/dev/null || { cat "$work/viewer.log" >&2; exit 1; }
  sleep 0.1
done
sleep 2  # the last update on the screen
id=$(xwininfo -root -tree | sed -n 's/^ *\(0x[0-9a-f]*\) "SlamDunk - 7scenes.rawlog".*/\1/p' | head -1)
[ -n "$id" ] || { echo "make-viewer-screenshot: no viewer window" >&2; exit 1; }
# A palette of 256 colours keeps the PNG small (the README's budget: under 300 KB).
import -window "$id" -colors 256 PNG8:docs/live-viewer.png
xdotool windowfocus --sync "$id" key q
wait "$app"
app=
ls -l docs/live-viewer.png
