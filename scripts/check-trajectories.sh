#!/usr/bin/env bash
# Behaviour check for refactorings: runs slamdunk-rawlog (default INI) on a fixed set of
# sequences and compares each trajectory byte for byte with a reference run.
#   scripts/check-trajectories.sh BIN_DIR OUT_DIR              (writes OUT_DIR/<sequence>.txt)
#   scripts/check-trajectories.sh BIN_DIR OUT_DIR REFERENCE_DIR (and compares with it; exit 1
#                                                               when any trajectory differs)
# The inputs are prepared once in $INPUTS (default build/check-inputs) with BIN_DIR's tools and
# reused, so two builds are compared on the same rawlogs. SEQUENCES selects a subset.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n 2,8p "$0" >&2; exit 2; }
bin=$1 out=$2 reference=${3:-}
data=${SLAMDUNK_DATA_DIR:-$(pwd)/../shared/data}
inputs=${INPUTS:-build/check-inputs}
[ -x "$bin/slamdunk-rawlog" ] || { echo "no $bin/slamdunk-rawlog (build first)" >&2; exit 2; }
mkdir -p "$inputs" "$out"

source scripts/lib/rawlog.sh
convert() {  # convert NAME SEQ CAMERA: once, so that every build is compared on the same input
  [ -f "$inputs/$1.rawlog" ] && return 0
  [ -d "$data/$2" ] || { echo "missing recording: $data/$2" >&2; exit 2; }
  convert_recording "$bin" "$data/$2" "config-ini/cameras/$3" "$inputs/$1.rawlog"
}
convert 7scenes 7scenes/seq-1000f 7scenes.ini
convert fr1_xyz_400f tum/fr1_xyz_400f tum-fr1.ini
[ -f "$inputs/synthetic_loop_kinect.rawlog" ] ||
  "$bin/synthetic-rgbd" "$inputs/synthetic_loop.rawlog" \
    --kinect-twin "$inputs/synthetic_loop_kinect.rawlog" -q >/dev/null
# A hand-held camera (rolling shutter, depth 5 ms after colour): the sensor-timing paths.
[ -f "$inputs/handheld_shake_kinect.rawlog" ] ||
  "$bin/synthetic-rgbd" "$inputs/handheld_shake_exact.rawlog" \
    --kinect-twin "$inputs/handheld_shake_kinect.rawlog" --trajectory shake --hand-held \
    --supersampling 1 --external-images -q >/dev/null

status=0
for name in ${SEQUENCES:-7scenes fr1_xyz_400f synthetic_loop synthetic_loop_kinect handheld_shake_kinect}; do
  ini=config-ini/slamdunk-default.ini
  if [[ $name == handheld_* ]]; then
    ini=$out/handheld.ini
    printf '[tracker]\ndepth_time_offset_ms = 5\n' > "$ini"
  fi
  "$bin/slamdunk-rawlog" "$inputs/$name.rawlog" --config "$ini" -t "$out/$name.txt" -q >/dev/null
  if [ -n "$reference" ]; then
    if cmp -s "$out/$name.txt" "$reference/$name.txt"; then
      echo "$name: identical"
    else
      echo "$name: DIFFERS from $reference/$name.txt"
      status=1
    fi
  else
    echo "$name: $(sha256sum < "$out/$name.txt" | cut -c1-16)"
  fi
done
exit $status
