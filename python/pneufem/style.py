"""The figures' colours for matplotlib: the palette pneufem's own figures draw with (viz/svg_plot.cpp),
so that a figure redrawn from the CSVs written beside every SVG (they carry the numbers, not the
styles) looks like pneufem's. Okabe & Ito's colour-blind safe palette, yellow left out (too light on
white); one colour per trial, measured and model alike, as the compare report draws them.

    import matplotlib.pyplot as plt
    from pneufem import style
    style.use()                                         # the palette as matplotlib's colour cycle
    ax.plot(t, measured, ".", color=style.color(trial - 1))
    ax.plot(t, model, "-", color=style.color(trial - 1))  # the same trial, the same colour

matplotlib is imported only by use(): the package itself needs numpy alone.
"""

# Okabe, M. & Ito, K. (2008), Color Universal Design: blue, vermilion, bluish green, reddish purple,
# orange, sky blue, black, grey; the order of viz/svg_plot.cpp's kPalette (python/tests/test_style.py
# checks that the two agree).
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#999999")
# The colour of reference lines (a noise floor, a fit's data range), as pneufem's reports draw them.
GREY = "#999999"


def color(i):
    """Colour i of the palette (cycles after 8): give a series the index of its trial (from 0), so
    that its measured and model curves share the colour."""
    return PALETTE[int(i) % len(PALETTE)]


def use():
    """Sets matplotlib's colour cycle to the palette, for series drawn without a colour."""
    import matplotlib
    matplotlib.rcParams["axes.prop_cycle"] = matplotlib.cycler(color=list(PALETTE))
