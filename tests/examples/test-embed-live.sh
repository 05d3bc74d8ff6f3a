#!/usr/bin/env bash
# Configures and builds examples/embed-live against the build tree's CMake package, as an
# application outside this project would (find_package(slamdunk) + slamdunk::live), runs it on
# the synthetic sweep in both shapes (polling, pushing) and checks that it prints poses.
# Usage: test-embed-live.sh SOURCE_DIR BUILD_DIR [EXTRA_COMPILER_FLAGS]
set -euo pipefail
src=$1
build=$2
flags=${3:-}
rawlog=$build/test-data/synthetic_sweep.rawlog
out=$build/test-scratch/EmbedLiveExample
rm -rf "$out"
mkdir -p "$out"
if [ ! -f "$rawlog" ]; then
  echo "test-embed-live: $rawlog was not prepared (prepare_test_data fixture)" >&2
  exit 1
fi

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
step() {  # step NAME COMMAND...: runs it, shows its log only on failure
  local name=$1
  shift
  if ! "$@" >"$out/$name.log" 2>&1; then
    echo "test-embed-live: $name failed:" >&2
    cat "$out/$name.log" >&2
    exit 1
  fi
}
step configure cmake -S "$src/examples/embed-live" -B "$out/build" "${generator[@]}" \
  -Dslamdunk_DIR="$build" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags"
step build cmake --build "$out/build"

check() {  # check LOG PREFIX MIN_POSES
  local log=$1 prefix=$2 min=$3 poses tracked
  poses=$(grep -c "^$prefix pose t=" "$log" || true)
  tracked=$(sed -n 's/^done: \([0-9]*\) frames tracked.*/\1/p' "$log")
  echo "test-embed-live: $prefix: $poses poses printed, ${tracked:-no} frames tracked"
  # Real-time replay: a machine busy with other work may drop frames, hence only 20 tracked.
  if [ "$poses" -lt "$min" ] || [ -z "$tracked" ] || [ "$tracked" -lt 20 ]; then
    echo "test-embed-live: expected at least $min '$prefix pose' lines and 20 tracked frames:" >&2
    cat "$log" >&2
    exit 1
  fi
  # A pose line carries both conventions with numbers.
  grep -m1 "^$prefix pose" "$log"
  grep -qE "^$prefix pose t=[0-9.]+ tracked +optical \[-?[0-9.]+ -?[0-9.]+ -?[0-9.]+\] mrpt-sensor \[x=-?[0-9.]+ " "$log" ||
    { echo "test-embed-live: no well-formed tracked pose line" >&2; exit 1; }
}
step run-polled "$out/build/embed-live" "$rawlog"
check "$out/run-polled.log" polled 10
step run-push "$out/build/embed-live" "$rawlog" --push
check "$out/run-push.log" callback 3  # one line per 10 frames tracked
echo "test-embed-live: ok"
