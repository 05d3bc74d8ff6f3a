# Sourced by the benchmark scripts, from the repository root: the built tools, the shared
# recordings, the work folder, and the helpers for rawlogs and JSON summaries.
data=${SLAMDUNK_DATA_DIR:-$(pwd)/../shared/data}
bin=build/bin
work=build/benchmark
mkdir -p "$work"
source scripts/lib/rawlog.sh
source scripts/lib/summary.sh
