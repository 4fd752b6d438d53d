#!/usr/bin/env bash
# A Chrome trace (Perfetto, chrome://tracing) of 60 steps: every system run on every thread.
# Uses the pit-character scene when the runner has it, the pour otherwise.
#   SPHERES  (default 100000)
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
build_targets ballpit
n="${SPHERES:-100000}"
scene=pour
if "$BUILD/app/ballpit" run --scene pit-character --spheres 10 --steps 1 --no-table --no-progress >/dev/null 2>&1; then
  scene=pit-character
fi
trace="$REPORTS/trace_${scene}_${n}_60steps.json"
"$BUILD/app/ballpit" run --scene "$scene" --spheres "$n" --steps 60 --threads 2 --trace "$trace"
log "wrote $trace (open it in https://ui.perfetto.dev)"
