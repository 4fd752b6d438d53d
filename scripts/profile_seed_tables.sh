#!/usr/bin/env bash
# The original report's frame-rate tables as simulation cost per step: pour at n = 50..400 with
# our grid, our naive narrowphase (the original's k = 1) and no collisions, extended to 1M; and
# the character rows (n = 10..250) when the runner has --scene pit-character.
# Writes $REPORTS_DIR/seed_tables.{jsonl,md} (default profiling/reports/). Extra arguments go to
# seed_tables: --steps S (rows up to n = 10,000, default 600), --big-steps S (rows above, default
# 60: the report says so), --sizes / --max-spheres (extension rows, default 1k..1M), --threads.
# A size over the memory budget is not run and the report lists it (engine/memory_budget.h;
# BALLPIT_MEMORY_LIMIT_MB lowers the budget).
#   CHARACTER_SIZES  n of the character rows (default "10 50 100 150 200 250")
#   CHARACTER_STEPS  steps of the scripted path per character row (default 600, the whole path)
# A smoke run at small sizes:
#   REPORTS_DIR=/tmp/seed CHARACTER_SIZES="10 50" CHARACTER_STEPS=30 \
#     scripts/profile_seed_tables.sh --sizes 1000,10000 --steps 30 --big-steps 5
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
build_targets seed_tables ballpit
out="$REPORTS/seed_tables.jsonl"
"$BUILD/profiling/seed_tables" "$@" >"$out.tmp"
mv "$out.tmp" "$out"
character="$REPORTS/seed_tables_character.jsonl"
rm -f "$character"
if "$BUILD/app/ballpit" run --scene pit-character --spheres 10 --steps 1 --no-table --no-progress >/dev/null 2>&1; then
  : >"$character.tmp"
  for n in ${CHARACTER_SIZES:-10 50 100 150 200 250}; do
    for mode in grid naive; do
      flag=""
      [ "$mode" = naive ] && flag="--naive"
      log "pit-character n=$n $mode"
      "$BUILD/app/ballpit" run --scene pit-character --spheres "$n" --steps "${CHARACTER_STEPS:-600}" --threads 2 $flag \
        --no-table --no-progress | sed "s/^{/{\"mode\":\"$mode\",/" >>"$character.tmp"
    done
  done
  mv "$character.tmp" "$character"
else
  log "the runner has no --scene pit-character yet: character rows left out"
fi
"$PYTHON" "$ROOT/profiling/make_seed_tables.py" "$out" --origin "$ROOT/profiling/origin_fps.csv" \
  --character "$character" --md "$REPORTS/seed_tables.md"
log "wrote $REPORTS/seed_tables.md"
