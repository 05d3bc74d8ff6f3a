#!/usr/bin/env bash
# Builds the rawlogs the application tests run on, once per build tree:
#   real recordings from the shared data folder and the project's own synthetic sequences.
#   A missing recording is skipped with a message, or fails the preparation (naming the folder)
#   under SLAMDUNK_REQUIRE_DATA=1, as in CI. SLAMDUNK_LONG_TESTS=1 (scripts/test-long.sh) also
#   renders the whole 2.5-minute hand-held scan (2 GB); CI renders its first 20 s.
#   Usage: prepare-test-data.sh BIN_DIR DATA_DIR OUT
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
    if [ "${SLAMDUNK_REQUIRE_DATA:-0}" = 1 ]; then
      echo "prepare-test-data: error: $seq not found (SLAMDUNK_REQUIRE_DATA=1): set" \
        "SLAMDUNK_DATA_DIR to the shared data folder" >&2
      return 1
    fi
    echo "prepare-test-data: $seq not found: tests on $name will be skipped"
    return
  fi
  # Converted again when the camera file or the converter changed (they decide the depth
  # registration).
  if [ "$out/$name.rawlog" -nt "$cam" ] && [ "$out/$name.rawlog" -nt "$bin/tum2rawlog" ]; then
    echo "prepare-test-data: $name.rawlog ready"
    return
  fi
  "$bin/tum2rawlog" "$seq" "$out/$name.rawlog" --camera "$cam" --external-images -q "$@"
}

# A render is made again when the renderer or its arguments changed: the stamp beside the
# rawlog holds a hash of synthetic-rgbd, the synthetic module's library and the arguments.
renderer_hash() {
  local lib
  lib=$(ldd "$bin/synthetic-rgbd" | awk '/libslamdunk_synthetic/ {print $3}')
  md5sum "$bin/synthetic-rgbd" ${lib:+"$lib"} | cut -d' ' -f1
}
renderer=$(renderer_hash)  # once: the jobs' subshells read it
render_stamp() {  # render_stamp ARGS...
  { echo "$renderer"; echo "$*"; } | md5sum | cut -d' ' -f1
}

rendered() {  # rendered NAME STAMP RAWLOG...: true when every rawlog is there and up to date
  local name=$1 stamp=$2
  shift 2
  for f in "$@"; do [ -f "$f" ] || return 1; done
  [ "$(cat "$out/.$name.render" 2>/dev/null)" = "$stamp" ]
}

synthetic() {  # synthetic NAME TRAJECTORY [EXTRA_ARGS...]
  local name=$1 trajectory=$2 stamp
  shift 2
  stamp=$(render_stamp --trajectory "$trajectory" "$@")
  if rendered "$name" "$stamp" "$out/$name.rawlog"; then
    echo "prepare-test-data: $name.rawlog ready"
    return
  fi
  # (Run through start_job's `||`, where set -e does not apply: a failure must return itself.)
  "$bin/synthetic-rgbd" "$out/$name.rawlog" --trajectory "$trajectory" -q "$@" || return 1
  echo "$stamp" >"$out/.$name.render"
}

synthetic_pair() {  # synthetic_pair NAME TRAJECTORY [EXTRA_ARGS...]: NAME and NAME_kinect
  local name=$1 trajectory=$2 stamp
  shift 2
  stamp=$(render_stamp --trajectory "$trajectory" --kinect-twin "$@")
  if rendered "$name" "$stamp" "$out/$name.rawlog" "$out/${name}_kinect.rawlog"; then
    echo "prepare-test-data: $name.rawlog and ${name}_kinect.rawlog ready"
    return
  fi
  # One render for both: the twin is byte for byte what --kinect-depth alone would write.
  "$bin/synthetic-rgbd" "$out/$name.rawlog" --trajectory "$trajectory" \
    --kinect-twin "$out/${name}_kinect.rawlog" -q "$@" || return 1
  echo "$stamp" >"$out/.$name.render"
}

# Independent jobs, as many at once as there are cores, the longest first: run one after the
# other they took 21 minutes of a CI run while the rest of the suite waited for them. A failed
# job is named in $failed and fails the whole preparation once every job has ended.
# One thread per render (Mesa's llvmpipe): the jobs already keep every core busy, and its
# threads only add switching (two renders at once took 12 % longer with them). Same images.
export LP_NUM_THREADS=${LP_NUM_THREADS:-1}
failed=$out/.failed-jobs
rm -f "$failed"
max_jobs=$(nproc 2>/dev/null || echo 2)
start_job() {  # start_job COMMAND...
  while [ "$(jobs -rp | wc -l)" -ge "$max_jobs" ]; do wait -n || true; done
  ( "$@" || echo "$*" >>"$failed" ) &
}

# Hand-held motion through a hand-held camera (blur, rolling shutter, auto exposure, depth offset;
# the exposure averages several renders, which also smooths edges: no supersampling needed).
# The sequences keep their images beside the rawlog (a Kinect twin hard-links the colour images
# of its exact twin), colour as JPEG of quality 95: a rendered image with noise and blur takes
# 600 KB as PNG and 180 KB so, and the ground truth, the depth and the camera effects stay
# exact. The sweep embeds its images: MRPT's own rawlog grabber (CCameraSensor), which a test
# feeds it to, does not find external ones.
# The whole 2.5-minute scan (4500 frames, about 5 minutes and 2 GB for the pair) only for the
# long runs; CI's is its first 20 s (600 frames, a quarter of the first lap).
handheld=(--hand-held --supersampling 1 --external-images --jpeg-quality 95)
if [ "${SLAMDUNK_LONG_TESTS:-0}" = 1 ]; then
  start_job synthetic_pair handheld_scan scan "${handheld[@]}"
fi
start_job convert 7scenes 7scenes/seq-1000f 7scenes.ini
start_job synthetic_pair handheld_scan20s scan --first-frames 600 "${handheld[@]}"
# The dwell's first 16 s (480 frames), through the Kinect-like camera alone: its first coverage
# ends near 8 s.
start_job synthetic handheld_dwell16s_kinect dwell --first-frames 480 --kinect-depth \
  "${handheld[@]}"
start_job synthetic_pair handheld_rotations rotations "${handheld[@]}"
start_job synthetic_pair handheld_shake shake "${handheld[@]}"
start_job synthetic_pair synthetic_loop loop --external-images --jpeg-quality 95
start_job synthetic synthetic_sweep sweep
# A second lap round the same loop at another pace (330 frames for the loop's 400: other poses,
# other images), localized in the first lap's map.
start_job synthetic synthetic_loop_lap2 loop --frames 330 --external-images --jpeg-quality 95
# The office tour (55 m round four rooms) at three times walking pace, through a Kinect-like
# camera whose stated focal length is 3 % off: the odometry drifts by decimetres, more than the
# active window can close at the return (loop closing's tests). The long runs' alone: CI closes
# the loop of the same tour with the corridor from B to C painted almost plain (7 m with few
# features), which needs everything the plain one does and more.
if [ "${SLAMDUNK_LONG_TESTS:-0}" = 1 ]; then
  start_job synthetic tour_drift tour --frames 1100 --kinect-depth --stated-focal-error 3 \
    --external-images --jpeg-quality 95 --supersampling 1
fi
start_job synthetic tour_drift_bare tour --frames 1100 --kinect-depth --stated-focal-error 3 \
  --bare-corridor --external-images --jpeg-quality 95 --supersampling 1
# Two sessions of one walk through the office (the tour's frames 250-499, then 100-399): the
# second starts where the first one's map does not reach, and walks into it 4 m later.
start_job synthetic tour_session1 tour --frames 1100 --skip-frames 250 --first-frames 250 \
  --external-images --jpeg-quality 95 --supersampling 1
start_job synthetic tour_session2 tour --frames 1100 --skip-frames 100 --first-frames 300 \
  --external-images --jpeg-quality 95 --supersampling 1
# The tour through an office whose room C is a copy of room A (--twin-rooms): the same views
# 20 m apart, which must not be taken for a loop. Its frames 900-1099 and 350-549 are also two
# sessions there (the corridor from D into A, then the one from B into C: the same walk turned
# half a turn; C must not be joined to A): the tests take them with --first-frame/--max-frames,
# the images being those a render of the stretch alone gives, byte for byte.
start_job synthetic tour_twins tour --frames 1100 --twin-rooms --external-images \
  --jpeg-quality 95 --supersampling 1
start_job convert fr1_xyz_400f tum/fr1_xyz_400f tum-fr1.ini
# The same hand at a third and a sixth of the frame rate: three and six times the motion between
# frames.
start_job convert fr1_xyz_400f_stride3 tum/fr1_xyz_400f tum-fr1.ini --stride 3
start_job convert fr1_xyz_400f_stride6 tum/fr1_xyz_400f tum-fr1.ini --stride 6
start_job convert fr1_desk_9f tum/fr1_desk_9f tum-fr1.ini
start_job convert fr3_cabinet_58kf tum/fr3_cabinet_58kf tum-fr3.ini
wait
if [ -f "$failed" ]; then
  echo "prepare-test-data: failed: $(tr '\n' ';' <"$failed")" >&2
  exit 1
fi
ls -l "$out"
