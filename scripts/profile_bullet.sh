#!/usr/bin/env bash
# Bullet side by side with ballpit on the pour, in one run per size, at 10k and 100k spheres:
# ms/step, max and mean penetration, kinetic energy and when each engine settled. Bullet needs
# 0.5 to 0.8 s a step at 10k and 2.6 to 7.7 s at 100k on the 2-core hosts measured, so both
# sizes run shortened: 120 steps (2 s) at 10k and 90 steps (1.5 s) at 100k, past the collapse
# (~1 s) and the time ballpit's pour settles at either size (~1.2-1.3 s); about 1 and 4 to 12
# minutes of Bullet. The report states the steps of every size and whether each engine had
# settled by its end.
# Writes $REPORTS_DIR/bullet.{jsonl,md} (default profiling/reports/).
#   BULLET_RUNS  "N:STEPS ..." (default "10000:120 100000:90"; "10000:600" for the whole pour,
#                about 8 minutes of Bullet; a smoke run: BULLET_RUNS="1000:20 2000:10")
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
build_targets bullet_pour
runs="${BULLET_RUNS:-10000:120 100000:90}"
out="$REPORTS/bullet.jsonl"
: >"$out.tmp"
for run in $runs; do
  n=${run%%:*}
  steps=${run##*:}
  log "pour n=$n steps=$steps (Bullet and ballpit)"
  "$BUILD/profiling/bullet_pour" --spheres "$n" --steps "$steps" | tee /dev/stderr | grep '^{' >>"$out.tmp"
done
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/make_bullet_report.py" "$out" --runs "$runs" --md "$REPORTS/bullet.md"
log "wrote $REPORTS/bullet.md"
