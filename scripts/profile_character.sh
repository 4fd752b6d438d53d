#!/usr/bin/env bash
# The character's cost: shared/SCENES.md's pit-character against the same pit without the
# character, at 10k, 100k and 1M balls, one JSON report line per run: the character's own
# systems (character_ms_per_step) and what its colliders add to the physics.
# Writes $REPORTS_DIR/character.{jsonl,md} (default profiling/reports/).
#   RUNS     "N:SETTLE:STEPS ..." (default "10000:300:600 100000:300:600 1000000:300:120": the 1M
#            pit settles as long as the others, since its pile is as deep, but walks only the
#            path's first 2 s, about 9 minutes for both of its runs on 2 cores; the report says so)
#   THREADS  (default: nproc)
# A smoke run: REPORTS_DIR=/tmp/character RUNS="3000:30:30" scripts/profile_character.sh
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
RUNS="${RUNS:-10000:300:600 100000:300:600 1000000:300:120}"
THREADS="${THREADS:-$(nproc)}"
build_targets ballpit
out="$REPORTS/character.jsonl"
: >"$out.tmp"
tag() {  # adds the run's label and settle steps to the report line on stdin
  "$PYTHON" -c 'import json,sys; r=json.loads(sys.stdin.read()); r["run"]=sys.argv[1]; r["settle_steps"]=int(sys.argv[2]); print(json.dumps(r))' "$@"
}
for run in $RUNS; do
  IFS=: read -r n settle steps <<<"$run"
  log "N=$n with the character: $settle settle + $steps steps, $THREADS threads"
  with="$("$BUILD/app/ballpit" run --scene pit-character --spheres "$n" --steps "$steps" \
    --set character.settle_steps="$settle" --threads "$THREADS" --no-progress --no-table | tail -n 1)"
  echo "$with" | tag with "$settle" >>"$out.tmp"
  # Without: the same scene and pit (the character widens a small one) with the character off.
  # Nothing then stands while the pour settles, so the run is settle + 2 x steps long and its
  # second half (steps settle + steps .. end, settled as long as the other's path) is compared.
  half="$(echo "$with" | "$PYTHON" -c 'import json,sys; print(json.loads(sys.stdin.read())["pit_half_width_m"])')"
  log "N=$n without the character: $((settle + 2 * steps)) steps"
  "$BUILD/app/ballpit" run --scene pit-character --spheres "$n" --steps "$((settle + 2 * steps))" \
    --set features.character=false --set pit.half_width="$half" --threads "$THREADS" \
    --no-progress --no-table | tail -n 1 | tag without "$settle" >>"$out.tmp"
done
mv "$out.tmp" "$out"
"$PYTHON" "$ROOT/profiling/make_character_report.py" "$out" --md "$REPORTS/character.md"
log "wrote $REPORTS/character.md"
