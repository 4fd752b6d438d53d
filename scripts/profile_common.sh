# Shared by scripts/profile_*.sh (sourced, not run): where the tree, the build and the reports
# are, and how to build only the targets a study needs.
#   BUILD_DIR    build directory (default: <repo>/build, the README's)
#   REPORTS_DIR  where the reports go (default: <repo>/profiling/reports; a smoke run of a
#                script at small sizes points it at a temporary folder)
#   JOBS         parallel build jobs (default: nproc)
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BUILD_DIR:-$ROOT/build}"
REPORTS="${REPORTS_DIR:-$ROOT/profiling/reports}"
PYTHON=/usr/bin/python3  # Debian's python3 with python3-matplotlib
mkdir -p "$REPORTS"
# As scripts/run.sh: OpenMP threads wait passively unless told otherwise, because spinning
# barriers crawl when the cores are shared. The reports print the policy they ran with;
# OMP_WAIT_POLICY=active (or any value) overrides, and the scaling study runs both.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"

build_targets() {
  if [ ! -f "$BUILD/CMakeCache.txt" ]; then
    cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
  fi
  cmake --build "$BUILD" -j"${JOBS:-$(nproc)}" --target "$@" >/dev/null
}

log() { echo "[$(basename "$0" .sh)] $*" >&2; }
