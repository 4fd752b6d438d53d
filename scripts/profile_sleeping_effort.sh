#!/usr/bin/env bash
# What keeps the pit awake while the marine walks, and whether more solver effort buys sleep
# (issue 39): the pit-character at CHARACTER_N settled SETTLE steps around him standing (once with
# sleeping on, once off, each saved as a snapshot), then the first STEPS of his path from each,
# with sleeping on at several solver settings, one after the other. One JSON report line a case
# into $REPORTS_DIR/sleeping_effort.jsonl, and a table on stdout: ms/step, deepest overlap, balls
# awake on average and at the end. The cost of a step follows the awake balls, so more substeps
# may cost less if they let more of the pit sleep.
#   CHARACTER_N (default 100000)   SETTLE (default 3000)   STEPS (default 300)
#   SETTINGS    (default "--substeps=4 --substeps=6 --substeps=8 --solve-sweeps=2")
#   THREADS     (default: nproc)
# A smoke run: REPORTS_DIR=/tmp/effort CHARACTER_N=3000 SETTLE=60 STEPS=30 scripts/profile_sleeping_effort.sh
set -euo pipefail
source "$(dirname "$0")/profile_common.sh"
CHARACTER_N="${CHARACTER_N:-100000}"
SETTLE="${SETTLE:-3000}"
STEPS="${STEPS:-300}"
SETTINGS="${SETTINGS:---substeps=4 --substeps=6 --substeps=8 --solve-sweeps=2}"
THREADS="${THREADS:-$(nproc)}"
build_targets ballpit
snapshots="$(mktemp -d)"
trap 'rm -rf "$snapshots"' EXIT
for sleeping in true false; do
  log "settling pit-character N=$CHARACTER_N for $SETTLE steps, sleeping $sleeping"
  "$BUILD/app/ballpit" run --scene "$ROOT/scenes/pit_character.json" --set populations.0.count="$CHARACTER_N" \
    --set character.settle_steps="$SETTLE" --set features.sleeping="$sleeping" --threads "$THREADS" --steps 1 \
    --save "$snapshots/$sleeping.snap" --no-progress --no-table >/dev/null
done
out="$REPORTS/sleeping_effort.jsonl"
: >"$out.tmp"
tag() {  # adds the case's name to the report line on stdin
  "$PYTHON" -c 'import json,sys; r=json.loads(sys.stdin.read()); r["case"]=sys.argv[1]; print(json.dumps(r))' "$1"
}
log "sleeping off, the solver's default"
"$BUILD/app/ballpit" run --load "$snapshots/false.snap" --steps "$STEPS" --threads "$THREADS" --no-progress \
  --no-table | tail -n 1 | tag "sleeping off" >>"$out.tmp"
for setting in $SETTINGS; do
  log "sleeping on, $setting"
  "$BUILD/app/ballpit" run --load "$snapshots/true.snap" --steps "$STEPS" --threads "$THREADS" "$setting" \
    --no-progress --no-table | tail -n 1 | tag "sleeping on, $setting" >>"$out.tmp"
done
mv "$out.tmp" "$out"
lscpu | grep -m1 'Model name' || true
"$PYTHON" - "$out" <<'EOF'
import json, sys
print(f"{'case':34} {'ms first':>9} {'ms second':>10} {'max pen/r':>10} {'awake mean':>11} {'awake end':>10}")
for line in open(sys.argv[1]):
    r = json.loads(line)
    awake = r.get("awake_mean", r["spheres"])
    print(f"{r['case']:34} {r['ms_per_step_pour_median']:9.2f} {r['ms_per_step_settled_median']:10.2f} "
          f"{r['max_penetration_r']:10.4f} {awake:11.0f} {r.get('awake_final', r['spheres']):10}")
EOF
