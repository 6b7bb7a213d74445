"""pneufem.style: the palette of pneufem's own figures for matplotlib, one definition per language that
agree (viz/svg_plot.cpp's kPalette is read from the source tree, PNEUFEM_SOURCE_DIR)."""
import os
import pathlib
import re

import pytest

from pneufem import style


def test_the_palette_is_the_one_of_the_cpp_figures():
    source = pathlib.Path(os.environ["PNEUFEM_SOURCE_DIR"]) / "viz" / "svg_plot.cpp"
    m = re.search(r"kPalette\[\]\s*=\s*\{([^}]*)\}", source.read_text())
    assert m, f"no kPalette in {source}"
    assert list(style.PALETTE) == re.findall(r'"(#[0-9A-Fa-f]{6})"', m.group(1))
    assert style.GREY in style.PALETTE


def test_a_trial_keeps_its_colour_and_the_palette_cycles():
    assert style.color(0) == "#0072B2"
    assert style.color(1) == "#D55E00"
    assert style.color(len(style.PALETTE) + 1) == style.color(1)
    assert len(set(style.PALETTE)) == len(style.PALETTE)


def test_use_makes_the_palette_matplotlibs_colour_cycle():
    matplotlib = pytest.importorskip("matplotlib")
    saved = matplotlib.rcParams["axes.prop_cycle"]
    try:
        style.use()
        assert matplotlib.rcParams["axes.prop_cycle"].by_key()["color"] == list(style.PALETTE)
    finally:
        matplotlib.rcParams["axes.prop_cycle"] = saved
