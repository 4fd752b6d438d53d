#!/usr/bin/env bash
# Speed against error: sweeps the solver settings (substeps, push-out rate and speed cap, step
# size, restitution threshold) and tolerance mode (`--tolerance P`, P = 0.01, 0.003, 0.001) over
# bounce, Newton's cradle, the resting stack of 50, the elastic gas, the pour at 10k, 5 crowds
# spawned inside themselves, the pit-character at 5k, and a few points of the pour at 100k.
# Writes $REPORTS_DIR/speed_error.{jsonl,csv,png,md} (default profiling/reports/), including
# where the tolerance points land and why the default is the default. Takes roughly an hour
# on 2 cores. Extra arguments go to the speed_error program, e.g.
#   scripts/profile_speed_error.sh --cases bounce,cradle --points default,substeps=8,tolerance=0.01
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
build_targets speed_error
out="$REPORTS/speed_error.jsonl"
"$BUILD/profiling/speed_error" "$@" >"$out.tmp"
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/plot_speed_error.py" "$out" --csv "$REPORTS/speed_error.csv" \
  --png "$REPORTS/speed_error.png" --md "$REPORTS/speed_error.md"
log "wrote $REPORTS/speed_error.{jsonl,csv,png,md}"
