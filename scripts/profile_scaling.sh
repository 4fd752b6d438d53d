#!/usr/bin/env bash
# Scaling study: the canonical pour (`ballpit run --scene pour`) over N from 1k to 1M and threads
# 1..T, one JSON report line per run. Writes $REPORTS_DIR/scaling.{jsonl,csv,png,md} (default
# profiling/reports/).
#   SIZES      spheres (default "1000 3000 10000 30000 100000 300000 1000000")
#   THREADS    largest thread count T (default: nproc)
#   STEPS      steps per run (default 240: halves are steps 0-119 "pour", 120-239 "settled";
#              the pit has collapsed by step 60 at any N)
#   BIG_STEPS  steps for N >= BIG_FROM (default 120, to keep the 1M runs within minutes; the
#              report says which runs were shortened)
#   BIG_FROM   the N from which BIG_STEPS applies (default 1000000)
#   WAIT_POLICIES  OpenMP wait policies for runs on more than one thread (default "default
#              passive"): "default" runs with OMP_WAIT_POLICY unset (GNU OpenMP spins a while
#              before it sleeps: fastest on a quiet machine); "passive" sets it to passive
#              (scripts/run.sh's choice), slower on a quiet machine (each barrier wakes a
#              sleeping thread) but far less hurt when other processes share the cores.
#              1-thread runs use "default" only (no barrier partner to wait for).
# An N the runner refuses because it would not fit in memory (engine/memory_budget.h;
# BALLPIT_MEMORY_LIMIT_MB lowers the budget) is recorded as refused and the study goes on.
# A smoke run at small sizes:
#   REPORTS_DIR=/tmp/scaling SIZES="1000 3000" STEPS=20 BIG_FROM=3000 BIG_STEPS=10 scripts/profile_scaling.sh
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
SIZES="${SIZES:-1000 3000 10000 30000 100000 300000 1000000}"
THREADS="${THREADS:-$(nproc)}"
STEPS="${STEPS:-240}"
BIG_STEPS="${BIG_STEPS:-120}"
BIG_FROM="${BIG_FROM:-1000000}"
build_targets ballpit
out="$REPORTS/scaling.jsonl"
err="$(mktemp)"
trap 'rm -f "$err"' EXIT
: >"$out.tmp"
for n in $SIZES; do
  steps=$STEPS
  [ "$n" -ge "$BIG_FROM" ] && steps=$BIG_STEPS
  for t in $(seq 1 "$THREADS"); do
    policies="default"
    [ "$t" -gt 1 ] && policies="${WAIT_POLICIES:-default passive}"
    for policy in $policies; do
      log "pour n=$n threads=$t steps=$steps wait=$policy"
      args=(run --scene pour --spheres "$n" --steps "$steps" --threads "$t" --no-table --no-progress)
      status=0
      if [ "$policy" = default ]; then
        line="$(env -u OMP_WAIT_POLICY "$BUILD/app/ballpit" "${args[@]}" 2>"$err")" || status=$?
      else
        line="$(OMP_WAIT_POLICY="$policy" "$BUILD/app/ballpit" "${args[@]}" 2>"$err")" || status=$?
      fi
      if [ "$status" -ne 0 ]; then
        if grep -q "needs about" "$err"; then  # over the memory budget: refused before allocating
          log "n=$n refused: $(cat "$err")"
          "$PYTHON" -c 'import json, sys; print(json.dumps({"spheres": int(sys.argv[1]), "steps": int(sys.argv[2]),
"refused": sys.argv[3].strip().removeprefix("ballpit: ")}))' "$n" "$steps" "$(cat "$err")" >>"$out.tmp"
          continue 3
        fi
        cat "$err" >&2
        exit "$status"
      fi
      grep '^{' <<<"$line" | sed "s/^{/{\"omp_wait_policy\":\"$policy\",/" >>"$out.tmp"
    done
  done
done
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/plot_scaling.py" "$out" --csv "$REPORTS/scaling.csv" --png "$REPORTS/scaling.png" --md "$REPORTS/scaling.md"
log "wrote $REPORTS/scaling.{jsonl,csv,png,md}"
