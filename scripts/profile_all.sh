#!/usr/bin/env bash
# Every profiling report, in order (about two hours on 2 cores): per-system benchmarks, scaling,
# speed against error, original-report tables, Bullet comparison, trace.
set -euo pipefail
dir="$(dirname "$0")"
"$dir/profile_systems.sh"
"$dir/profile_scaling.sh"
"$dir/profile_speed_error.sh"
"$dir/profile_seed_tables.sh"
"$dir/profile_bullet.sh"
"$dir/profile_trace.sh"
