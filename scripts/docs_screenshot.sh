#!/usr/bin/env bash
# Regenerates docs/screenshot.png: the default scene (`ballpit` with no arguments) rendered
# offscreen after FRAMES steps (default 240, 4 s), HUD included, then reduced to a 256-colour
# dithered palette (Debian's python3-pil) so the README's image stays under 500 KB.
#   BUILD_DIR  build directory (default: <repo>/build)
set -euo pipefail
# Passive OpenMP waiting: the app shares the CPU with the rasteriser's threads (llvmpipe), and
# on a busy machine spinning barriers cost more than the work (measured: 40,000 balls at
# 1060 ms a step spinning against 114 ms passive, on a shared 2-core box).
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BUILD_DIR:-$ROOT/build}"
tmp="$(mktemp --suffix=.png)"
trap 'rm -f "$tmp"' EXIT
"$BUILD/app/ballpit" --frames "${FRAMES:-240}" --screenshot "$tmp" >/dev/null
/usr/bin/python3 - "$tmp" "$ROOT/docs/screenshot.png" <<'PY'
import os, sys
from PIL import Image
src, dst = sys.argv[1], sys.argv[2]
im = Image.open(src).convert("RGB")
palette = im.quantize(colors=256, method=Image.Quantize.MEDIANCUT)
out = im.quantize(palette=palette, dither=Image.Dither.FLOYDSTEINBERG)
part = dst + ".part"
out.save(part, format="PNG", optimize=True)
os.replace(part, dst)  # never a half-written image in docs/
print(f"{dst}: {os.path.getsize(dst) // 1024} KB")
PY
