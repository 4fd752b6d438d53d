# examples/python/pour_profile.py runs: it pours, settles and writes its figure (a PNG).
import os
import pathlib
import subprocess
import sys

import pytest

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python" / "pour_profile.py"


def test_the_pour_profile_example_writes_its_figure(tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / "pile.png"
    out = subprocess.run([sys.executable, str(EXAMPLE), str(png), "--spheres", "500", "--steps", "120"],
                         check=True, capture_output=True, text=True, env=os.environ).stdout
    assert "500 balls" in out and "escaped 0" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
