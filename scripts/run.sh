#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job.
# With no arguments that is `ballpit` itself (the interactive pit where a display exists;
# without one, a headless run that prints the per-system report). Arguments go to ballpit.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
exec ./build/app/ballpit "$@"
