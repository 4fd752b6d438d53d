#!/usr/bin/env bash
# Each system alone (Google Benchmark): grid (sort, and sort + permute), narrowphase, solver,
# integrate, sleeping and substep control (--tolerance) on prepared worlds of N = 1k, 10k, 100k,
# 1M at 1 and 2 threads.
# Writes profiling/reports/systems.{csv,md}. Each benchmark runs 3 repetitions; the report gives
# the median and the fastest. Extra arguments go to every benchmark program and override those defaults (e.g.
# --benchmark_filter='n:1000/' --benchmark_repetitions=1). BALLPIT_BENCH_SETTLED_MAX=100000 adds the settled-pour
# world at 100k (made by running the pour 300 steps first).
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
systems=(grid narrowphase solver integrate sleeping substep_control)
build_targets "${systems[@]/#/bench_}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
for s in "${systems[@]}"; do
  log "bench_$s"
  "$BUILD/profiling/bench_$s" --benchmark_repetitions=3 --benchmark_display_aggregates_only=true \
    --benchmark_out="$tmp/$s.json" --benchmark_out_format=json "$@"
done
"$PYTHON" "$ROOT/profiling/report_systems.py" --csv "$REPORTS/systems.csv" --md "$REPORTS/systems.md" "$tmp"/*.json
log "wrote $REPORTS/systems.csv and systems.md"
