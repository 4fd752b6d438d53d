#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job.
# With no arguments that is `ballpit` itself (the interactive pit where a display exists;
# without one, a headless run that prints the per-system report). Arguments go to ballpit.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# OpenMP threads that wait spin a while, then sleep. libgomp's own default spins 300,000 rounds
# (milliseconds), which crawls when the cores are shared (other jobs, llvmpipe's threads), and
# waiting passively sleeps at once, so every parallel region and barrier wakes a thread. 10,000
# rounds keep the short waits of a step spinning (measured on a 2-core AMD EPYC, medians of
# runs in turn, settled pours: 3k 0.70 ms a step against 1.09 passive and 0.66 at libgomp's
# default; 10k 3.05 against 3.28 and 3.03; at 100k the waits are a small part of the step and
# the difference is within the host's noise) and cost llvmpipe nothing that matters (the
# 40,000-ball window scene offscreen: steps 13.3 and 13.1 ms against 14.3 and 13.7 passive,
# frames rendered in 158 and 156 ms against 150 and 151). Whatever the caller sets
# (OMP_WAIT_POLICY, GOMP_SPINCOUNT) wins; the test and profiling scripts wait passively, as
# their figures say.
if [ -z "${OMP_WAIT_POLICY:-}" ]; then export GOMP_SPINCOUNT="${GOMP_SPINCOUNT:-10000}"; fi
bash scripts/build.sh
exec ./build/app/ballpit "$@"
