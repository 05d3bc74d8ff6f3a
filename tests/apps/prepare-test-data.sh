#!/usr/bin/env bash
# Builds the rawlogs the application tests run on, once per build tree:
#   real recordings from the shared data folder (skipped with a message when absent) and the
#   project's own synthetic sequences (always). Usage: prepare-test-data.sh BIN_DIR DATA_DIR OUT
set -euo pipefail
bin=$1
data=${SLAMDUNK_DATA_DIR:-$2}
out=$3
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"

convert() {  # convert NAME SEQ_DIR CAMERA_INI [EXTRA_ARGS...]
  local name=$1 seq=$data/$2 cam=$src/config-ini/cameras/$3
  shift 3
  if [ ! -d "$seq" ]; then
    echo "prepare-test-data: $seq not found: tests on $name will be skipped"
    return
  fi
  # Converted again when the camera file changed (it decides the depth registration).
  if [ "$out/$name.rawlog" -nt "$cam" ]; then echo "prepare-test-data: $name.rawlog ready"; return; fi
  "$bin/tum2rawlog" "$seq" "$out/$name.rawlog" --camera "$cam" --external-images -q "$@"
}

synthetic() {  # synthetic NAME TRAJECTORY [EXTRA_ARGS...]
  local name=$1 trajectory=$2
  shift 2
  if [ -f "$out/$name.rawlog" ]; then echo "prepare-test-data: $name.rawlog ready"; return; fi
  "$bin/synthetic-rgbd" "$out/$name.rawlog" --trajectory "$trajectory" -q "$@"
}

convert 7scenes 7scenes/seq-1000f 7scenes.ini
convert fr1_xyz_400f tum/fr1_xyz_400f tum-fr1.ini
# The same hand at a third and a sixth of the frame rate: three and six times the motion between
# frames.
convert fr1_xyz_400f_stride3 tum/fr1_xyz_400f tum-fr1.ini --stride 3
convert fr1_xyz_400f_stride6 tum/fr1_xyz_400f tum-fr1.ini --stride 6
convert fr1_desk_9f tum/fr1_desk_9f tum-fr1.ini
convert fr3_cabinet_58kf tum/fr3_cabinet_58kf tum-fr3.ini
synthetic synthetic_loop loop
synthetic synthetic_sweep sweep
synthetic synthetic_loop_kinect loop --kinect-depth
# Hand-held motion through a hand-held camera (blur, rolling shutter, auto exposure, depth offset;
# the exposure averages several renders, which also smooths edges: no supersampling needed).
# The 2.5-minute scan (4500 frames, about 7 minutes each to render) keeps its images beside the
# rawlog, which then stays small enough to read quickly.
for t in rotations shake scan; do
  images=()
  [ "$t" = scan ] && images=(--external-images)
  synthetic handheld_$t $t --hand-held --supersampling 1 "${images[@]}"
  synthetic handheld_${t}_kinect $t --hand-held --supersampling 1 --kinect-depth "${images[@]}"
done
ls -l "$out"
