# Sourced by the scripts that run on the shared recordings: a TUM-layout recording converted to
# a rawlog (images beside it) with tum2rawlog.

# convert_recording BIN SEQ_DIR CAMERA_INI OUT.rawlog: converts, always.
convert_recording() {
  "$1/tum2rawlog" "$2" "$4" --camera "$3" --external-images -q >/dev/null
}

# prepare_recording BIN SEQ_DIR CAMERA_INI OUT.rawlog: converts unless OUT is newer than the
# camera file and the converter (they decide the depth registration); fails with a message when
# the recording is missing.
prepare_recording() {
  [ "$4" -nt "$3" ] && [ "$4" -nt "$1/tum2rawlog" ] && return 0
  [ -d "$2" ] || { echo "skipping $(basename "$4" .rawlog): $2 not found" >&2; return 1; }
  convert_recording "$@"
}
