#!/usr/bin/env bash
# Sleeping by region against none (issue 39): the same runs with sleeping off and on, one after
# the other, one JSON report line each, into $REPORTS_DIR/sleeping.{jsonl,md}:
# - the canonical pour at each N of POUR_NS (600 steps): is sleeping ever slower, and what does
#   it do to the error (max_penetration_r at the end)?
# - pit-character at CHARACTER_N with the marine, settled for SETTLE steps around him standing,
#   then his 600-step path (walk, turn, run, idle): ms/step, spheres awake on average.
#   POUR_NS      (default "1000 10000 100000")
#   CHARACTER_N  (default 100000)   SETTLE (default 3000: the 100k pit is still creeping at 1500)
#   THREADS      (default: nproc)
# A smoke run: REPORTS_DIR=/tmp/sleeping POUR_NS=1000 CHARACTER_N=3000 SETTLE=60 scripts/profile_sleeping.sh
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
POUR_NS="${POUR_NS:-1000 10000 100000}"
CHARACTER_N="${CHARACTER_N:-100000}"
SETTLE="${SETTLE:-3000}"
THREADS="${THREADS:-$(nproc)}"
build_targets ballpit
out="$REPORTS/sleeping.jsonl"
: >"$out.tmp"
tag() {  # adds the run's case and sleeping to the report line on stdin
  "$PYTHON" -c 'import json,sys; r=json.loads(sys.stdin.read()); r["case"]=sys.argv[1]; r["sleeping"]=sys.argv[2]=="true"; print(json.dumps(r))' "$@"
}
for n in $POUR_NS; do
  for sleeping in false true; do
    log "pour N=$n, sleeping $sleeping"
    flag=(); [ "$sleeping" = true ] && flag=(--sleeping)
    "$BUILD/app/ballpit" run --scene pour --spheres "$n" "${flag[@]}" --threads "$THREADS" --no-progress --no-table |
      tail -n 1 | tag pour "$sleeping" >>"$out.tmp"
  done
done
for sleeping in false true; do
  log "pit-character N=$CHARACTER_N, $SETTLE settle steps + the path, sleeping $sleeping"
  "$BUILD/app/ballpit" run --scene "$ROOT/scenes/pit_character.json" --set populations.0.count="$CHARACTER_N" \
    --set character.settle_steps="$SETTLE" --set features.sleeping="$sleeping" --threads "$THREADS" \
    --no-progress --no-table | tail -n 1 | tag pit-character "$sleeping" >>"$out.tmp"
done
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/make_sleeping_report.py" "$out" --md "$REPORTS/sleeping.md"
log "wrote $REPORTS/sleeping.md"
