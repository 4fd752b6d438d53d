#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job.
# With no arguments that is `ballpit` itself (the interactive pit where a display exists;
# without one, a headless run that prints the per-system report). Arguments go to ballpit.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Spinning OpenMP barriers crawl when cores are shared (other jobs, llvmpipe's threads):
# wait passively unless told otherwise.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
bash scripts/build.sh
exec ./build/app/ballpit "$@"
