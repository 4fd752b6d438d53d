#!/usr/bin/env bash
# The README's test command: installs what is missing, builds with warnings as errors, runs
# every test through ctest, then the scheduler and physics tests under ThreadSanitizer.
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
# The grid's 1-vs-2-thread comparison starts an OpenMP team in the uninstrumented libgomp,
# which TSan cannot see into; the normal suite above runs it.
for t in test_scheduler test_grid test_narrowphase test_solver; do
  OMP_NUM_THREADS=1 TSAN_OPTIONS="halt_on_error=1" "build-tsan/tests/$t" \
    --gtest_filter=-Grid.SameOrderForOneAndTwoThreads
done
echo "[test] all suites passed"
