"""The Python examples run as tests (ctest: python_examples): each script finishes, prints its
finding and writes its figure."""
import pathlib
import subprocess
import sys

import pytest

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
