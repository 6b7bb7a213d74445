"""The Python examples run as tests (ctest: python_examples): each script finishes, prints its
finding and writes its figure, drawn in pneufem's palette (pneufem.style) rather than matplotlib's."""
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from pneufem import style

HERE = pathlib.Path(__file__).parent


@pytest.mark.parametrize("script,figure,expect", [
    ("simulate_and_plot.py", "angles.png", "angle at 15 kPa"),
    ("sweep_and_plot.py", "sweep.png", "3 points"),
    ("compare_and_diagnose.py", "diagnosis.png", "missing effect viscoelastic"),
])
def test_example(tmp_path, script, figure, expect):
    r = subprocess.run([sys.executable, str(HERE / script), str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert expect in r.stdout, r.stdout
    assert (tmp_path / figure).stat().st_size > 10000
    # The figure's first series is drawn in the palette's first colour (a marker's or a bar's fill:
    # whole pixels of it), and nothing in matplotlib's default first colour (tab:blue).
    pixels = _rgb_pixels(tmp_path / figure)
    assert _count(pixels, style.color(0)) > 20
    assert _count(pixels, "#1F77B4") == 0


def _rgb_pixels(png):
    import matplotlib.image
    rgb = matplotlib.image.imread(str(png))[..., :3]
    return np.rint(rgb * 255).astype(int).reshape(-1, 3)


def _count(pixels, hex_colour):
    rgb = [int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)]
    return int(np.all(pixels == rgb, axis=1).sum())
