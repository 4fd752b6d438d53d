#!/usr/bin/env bash
# Bullet side by side with ballpit on the pour, in one run per size: 10k (120 steps) and 100k
# (30 steps) by default; Bullet needs about 0.8 s a step at 10k, so the runs are shortened and
# the report says so. Writes profiling/reports/bullet.{jsonl,md}.
#   BULLET_RUNS  "N:STEPS ..." (default "10000:120 100000:30")
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
build_targets bullet_pour
out="$REPORTS/bullet.jsonl"
: >"$out.tmp"
for run in ${BULLET_RUNS:-10000:120 100000:30}; do
  n=${run%%:*}
  steps=${run##*:}
  log "pour n=$n steps=$steps (Bullet and ballpit)"
  "$BUILD/profiling/bullet_pour" --spheres "$n" --steps "$steps" | tee /dev/stderr | grep '^{' >>"$out.tmp"
done
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/make_bullet_report.py" "$out" --md "$REPORTS/bullet.md"
log "wrote $REPORTS/bullet.md"
