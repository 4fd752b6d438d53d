#!/usr/bin/env bash
# The README's test command: installs what is missing, builds with warnings as errors, runs
# every test through ctest, then the scheduler and physics tests under ThreadSanitizer, the
# suite under AddressSanitizer + UndefinedBehaviorSanitizer, and a short fuzzing run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Spinning OpenMP barriers crawl when cores are shared (other jobs, llvmpipe's threads):
# wait passively unless told otherwise.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
bash scripts/build.sh -DBALLPIT_WERROR=ON
# Tests run one at a time: several use two threads each, and oversubscribed OpenMP barriers
# on a 2-core machine turn milliseconds into seconds.
(cd build && ctest --output-on-failure --timeout 1200)
# ThreadSanitizer: the scheduler (threads of its own) and the physics (OpenMP) suites.
# libgomp is not built with TSan, so OpenMP runs single-threaded there; the scheduler's own
# threads are fully checked.
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=Debug -DBALLPIT_SANITIZE=thread \
  -DBALLPIT_PROFILING=OFF -DBALLPIT_WERROR=ON >/dev/null
cmake --build build-tsan -j"$(nproc)" --target test_scheduler test_grid test_narrowphase test_solver
# Left out here (the normal suite above runs them): the grid's 1-vs-2-thread comparison and the
# solver's checks of each thread's share, of integrating in the sweeps and of teams of 2 to 4
# start an OpenMP team in the uninstrumented libgomp, which TSan cannot see into (it reports
# the team's reads of the caller's stack); the solver suite's pours (the 2,000-ball pile, the kept-frames check's
# two 1,000-ball pours, and the 1,500-ball pours that compare instruction sets and slab
# groupings) take many minutes each in this unoptimised build and, with one OpenMP thread, run
# only code the other solver tests run.
for t in test_scheduler test_grid test_narrowphase test_solver; do
  OMP_NUM_THREADS=1 TSAN_OPTIONS="halt_on_error=1" "build-tsan/tests/$t" \
    --gtest_filter=-Grid.SameOrderForOneAndTwoThreads:Solver.ALoadedPileDoesNotBoilAtFewSubsteps:Solver.KeptPairFramesGiveTheStateOfFramesRecomputedInEveryPass:Solver.EveryInstructionSetGivesTheSameState:Solver.HowSlabsAreGroupedChangesNoBit:Solver.DefaultGroupsGiveEachThreadAnEqualShare:Solver.IntegratingInTheSweepsChangesNoBit:Solver.AnyTeamGivesTheStateOfOneThread
done
# AddressSanitizer + UndefinedBehaviorSanitizer: the whole suite (GL, command line and fuzz
# replays included) in build-asan/. RelWithDebInfo: -O2 keeps it affordable, -g names lines.
# Undefined behaviour aborts the test that hits it (-fno-sanitize-recover, CMakeLists.txt).
# LeakSanitizer ignores third-party leaks only (scripts/lsan.supp says which and why).
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBALLPIT_SANITIZE=address,undefined \
  -DBALLPIT_PROFILING=OFF -DBALLPIT_WERROR=ON >/dev/null
cmake --build build-asan -j"$(nproc)"
# Left out here, and only here (the normal run above has them): the three longest scale tests,
# 1310 of the 1960 s the whole suite took under ASan + UBSan on 2 cores (the instrumented
# solver runs up to 25x slower), for no extra coverage: each repeats at scale code paths that
# shorter tests run instrumented. The rest takes about 11 minutes.
#  - PitCharacter.TenThousandBalls... (650 s): character pushing a pour; the 2,000-ball
#    PitCharacter.TheSameStateForOneAndTwoThreads and KinematicContact.* run the same systems.
#  - HardCases.GravityTurnedFullCircle... (400 s): 10,000 balls in a closed box; closed boxes
#    and set_gravity run in HardCases.AnElasticGas... and HardCases.SphereCollisions...
#  - Determinism.OneAndTwoThreads...SixHundredPourSteps (260 s): the two-thread pour runs in
#    Determinism.RepeatedRunsGiveTheSameStateHash and SubstepControl.OneAndTwoThreads...
asan_skip='^(PitCharacter\.TenThousandBallsArePushedAsideAndNoneIsLeftInsideOrEscapes'
asan_skip+='|HardCases\.GravityTurnedFullCircleSpillsNoBallFromAClosedBox'
asan_skip+='|Determinism\.OneAndTwoThreadsGiveTheSameStateHashAfterSixHundredPourSteps)$'
(cd build-asan && LSAN_OPTIONS="suppressions=$PWD/../scripts/lsan.supp" UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure --timeout 1200 -E "$asan_skip")
# Fuzzing: each file reader for a short while (scripts/fuzz.sh; longer runs by hand), from a
# fixed seed so the suite tries the same inputs each time (what it finds then comes from a
# change, not the dice); hand runs draw a fresh seed.
BALLPIT_FUZZ_SEED="${BALLPIT_FUZZ_SEED:-1}" bash scripts/fuzz.sh "${BALLPIT_FUZZ_SECONDS:-45}"
echo "[test] all suites passed"
