#!/usr/bin/env bash
# Solve sweeps against substeps: the speed-against-error study (scripts/profile_speed_error.sh)
# over every case, at the points that trade one for the other: the default, more sweeps at the
# default substeps, fewer substeps of more sweeps, and substeps alone on either side, all in one
# sitting so their costs compare. Writes profiling/reports/solve_sweeps/speed_error.{jsonl,csv,
# png,md} (REPORTS_DIR overrides the folder). Takes about five minutes on 2 cores.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
export REPORTS_DIR="${REPORTS_DIR:-$here/../profiling/reports/solve_sweeps}"
exec bash "$here/profile_speed_error.sh" \
  --points default,substeps=2,substeps=3,substeps=6,substeps=8,sweeps=2,sweeps=3,substeps=3,sweeps=2,substeps=2,sweeps=3 "$@"
