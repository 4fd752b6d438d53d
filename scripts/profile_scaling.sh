#!/usr/bin/env bash
# Scaling study: the canonical pour (`ballpit run --scene pour`) over N from 1k to 1M and threads
# 1..T, one JSON report line per run. Writes profiling/reports/scaling.{jsonl,csv,png,md}.
#   SIZES      spheres (default "1000 3000 10000 30000 100000 300000 1000000")
#   THREADS    largest thread count T (default: nproc)
#   STEPS      steps per run (default 240: halves are steps 0-119 "pour", 120-239 "settled";
#              the pit has collapsed by step 60 at any N)
#   BIG_STEPS  steps for N >= 1,000,000 (default 120, to keep the run within minutes)
#   WAIT_POLICIES  OpenMP wait policies for runs on more than one thread (default "default
#              passive"): "default" runs with OMP_WAIT_POLICY unset (GNU OpenMP spins a while
#              before it sleeps: fastest on an idle machine); "passive" sets it to passive
#              (scripts/run.sh's choice), which suffers far less when other processes share the
#              cores. 1-thread runs use "default" only (no barrier partner to wait for).
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
SIZES="${SIZES:-1000 3000 10000 30000 100000 300000 1000000}"
THREADS="${THREADS:-$(nproc)}"
STEPS="${STEPS:-240}"
BIG_STEPS="${BIG_STEPS:-120}"
build_targets ballpit
out="$REPORTS/scaling.jsonl"
: >"$out.tmp"
for n in $SIZES; do
  steps=$STEPS
  [ "$n" -ge 1000000 ] && steps=$BIG_STEPS
  for t in $(seq 1 "$THREADS"); do
    policies="default"
    [ "$t" -gt 1 ] && policies="${WAIT_POLICIES:-default passive}"
    for policy in $policies; do
      log "pour n=$n threads=$t steps=$steps wait=$policy"
      if [ "$policy" = default ]; then
        env -u OMP_WAIT_POLICY "$BUILD/app/ballpit" run --scene pour --spheres "$n" --steps "$steps" --threads "$t" \
          --no-table --no-progress
      else
        OMP_WAIT_POLICY="$policy" "$BUILD/app/ballpit" run --scene pour --spheres "$n" --steps "$steps" --threads "$t" \
          --no-table --no-progress
      fi | sed "s/^{/{\"omp_wait_policy\":\"$policy\",/" >>"$out.tmp"
    done
  done
done
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/plot_scaling.py" "$out" --csv "$REPORTS/scaling.csv" --png "$REPORTS/scaling.png" --md "$REPORTS/scaling.md"
log "wrote $REPORTS/scaling.{jsonl,csv,png,md}"
