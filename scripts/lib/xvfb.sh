# Sourced by the benchmark scripts that draw a window: starts a private virtual X server
# (Xvfb) on a free display, exports DISPLAY, and stops it (and removes $out) on exit.
# start_xvfb needs $out (a scratch folder) and a NAME for the error message.
start_xvfb() {  # start_xvfb NAME
  trap 'kill "$xvfb" 2>/dev/null || true; rm -rf "$out"' EXIT
  Xvfb :"$((100 + RANDOM % 800))" -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp -noreset \
    3>"$out/display" 2>"$out/xvfb.log" &
  xvfb=$!
  for _ in $(seq 100); do [ -s "$out/display" ] && break; sleep 0.1; done
  [ -s "$out/display" ] || { echo "$1: Xvfb did not start" >&2; cat "$out/xvfb.log" >&2; exit 1; }
  export DISPLAY=:$(cat "$out/display")
}

# start_gui_benchmark NAME APP RAWLOG: for a benchmark of APP on RAWLOG with a window: checks
# that the app is built and the rawlog prepared, makes the scratch folder $out and starts Xvfb.
start_gui_benchmark() {
  [ -x "$2" ] || { echo "$1: build first (scripts/build.sh)" >&2; exit 1; }
  [ -f "$3" ] || { echo "$1: $3 missing (ctest -R prepare_test_data)" >&2; exit 1; }
  out=$(mktemp -d)
  start_xvfb "$1"
}
