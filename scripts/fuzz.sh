#!/usr/bin/env bash
# Fuzzes the engine's file readers with libFuzzer: the scene-file parser, the snapshot loader and
# the model import (fuzz/*_target.cpp). Builds them with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build-fuzz/, writes seed corpora made by the engine itself,
# then runs each target for a bounded time.
# Usage: scripts/fuzz.sh [seconds-per-target]   (default 60; CI runs it briefly)
#        BALLPIT_FUZZ_SEED=N fixes libFuzzer's seed (default 0: a fresh one each run; the test
#        suite fixes it)
#
# A finding (a crash, a hang, a sanitizer report, an exception other than ballpit::Error) is
# saved under build-fuzz/run/findings/<target>/ and the script fails at the end. To keep one:
# fix the engine, copy the input to tests/fuzz_regressions/<target>/ and `ctest -L fuzz`
# replays it in the normal build. Reproduce one with build-fuzz/fuzz/fuzz_<target> FILE.
# The corpora grow in build-fuzz/run/corpus/ from run to run.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
seed="${BALLPIT_FUZZ_SEED:-0}"
bash scripts/setup.sh
targets=(scene_file snapshot model_import)

# OpenMP: one thread (a fuzz input is a few spheres), waiting passively on the shared cores.
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
# UBSan aborts (-fno-sanitize-recover, CMakeLists.txt); its reports carry a stack.
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DBALLPIT_FUZZ=ON -DBALLPIT_SANITIZE=address,undefined -DBALLPIT_WERROR=ON \
  -DBALLPIT_TESTS=OFF -DBALLPIT_APP=OFF -DBALLPIT_PROFILING=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target make_seeds "${targets[@]/#/fuzz_}"

run=build-fuzz/run
rm -rf "$run/seeds" "$run/tmp"
mkdir -p "$run/tmp"
build-fuzz/fuzz/make_seeds "$run/seeds"
# More seeds from files we ship or install: the scene files, and assimp's small cube .X files
# (text and binary; no skeleton, so refused, but they reach the .X parser's other branches).
cp scenes/*.json "$run/seeds/scene_file/"
cp /usr/share/assimp/models/X/test_cube_text.x /usr/share/assimp/models/X/test_cube_binary.x \
  "$run/seeds/model_import/"

# The model import runs in libFuzzer's fork mode, without per-input leak checks: assimp leaks
# what it built for every .X file it refuses (scripts/lsan.supp), hundreds of KiB an input,
# so one process would pass the memory limit within a minute and a leak check per input would
# cost more than the input. Fork mode restarts the worker when that memory runs out (an OOM
# there is assimp's leak, ignored); crashes, hangs and sanitizer reports still fail the run.
# The other targets leak nothing: any leak there is a finding.
mode_model_import=(-fork=1 -ignore_ooms=1 -ignore_timeouts=0 -ignore_crashes=0 -detect_leaks=0)
mode_scene_file=()
mode_snapshot=()

failed=()
for t in "${targets[@]}"; do
  mkdir -p "$run/corpus/$t" "$run/findings/$t"
  echo "[fuzz] $t for ${seconds}s"
  mode="mode_${t}[@]"
  # -timeout: an input slower than this is a hang. -rss_limit_mb: above this is a finding
  # (libFuzzer's default, written out). The temp files of fuzz/fuzz_target.h go to $run/tmp.
  rc=0
  TMPDIR="$run/tmp" LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp" \
    "build-fuzz/fuzz/fuzz_$t" -seed="$seed" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$run/findings/$t/" "${!mode}" \
    "$run/corpus/$t" "$run/seeds/$t" "tests/fuzz_regressions/$t" >"$run/$t.log" 2>&1 || rc=$?
  # Fork mode exits with the status of the last worker to end, even an ignored one: 71 is
  # libFuzzer's out-of-memory status. That is no finding while its final count shows no
  # timeouts and no crashes ("oom/timeout/crash: N/0/0").
  if ((rc == 71)) && [[ " ${!mode} " == *" -fork=1 "* ]] &&
      grep -E '^#[0-9]+:' "$run/$t.log" | tail -n 1 | grep -qE 'oom/timeout/crash: [0-9]+/0/0'; then
    rc=0
  fi
  if ((rc != 0)); then
    failed+=("$t")
    grep -v NEW_FUNC "$run/$t.log" | tail -n 60
  fi
  # Executions: the final stats of a plain run, the last status line of fork mode.
  grep -E '^stat::number_of_executed_units' "$run/$t.log" || grep -E '^#[0-9]+:' "$run/$t.log" | tail -n 1 || true
done
if ((${#failed[@]})); then
  echo "[fuzz] FINDINGS in: ${failed[*]} (inputs in $run/findings/, logs in $run/*.log)" >&2
  exit 1
fi
echo "[fuzz] no findings"
