"""The documentation's figures can be redrawn and are shown: every SVG in docs/figures has its plotted
series as a CSV beside it, every figure there is shown by a Markdown document (README.md or docs/),
and docs/figures/make_figures.sh makes every one of them (names it). Standard library only.

    python3 tests/docs/check_figures.py REPO_ROOT
    python3 tests/docs/check_figures.py --self-test   (fails on a made-up tree, as it must)
"""
import pathlib
import sys
import tempfile


def problems(root):
    root = pathlib.Path(root)
    figures = root / "docs" / "figures"
    docs = [root / "README.md"] + sorted((root / "docs").glob("*.md"))
    shown = "\n".join(p.read_text(encoding="utf-8") for p in docs if p.exists())
    script = (figures / "make_figures.sh").read_text(encoding="utf-8")
    out = []
    for fig in sorted(list(figures.glob("*.svg")) + list(figures.glob("*.png"))):
        if fig.suffix == ".svg" and not fig.with_suffix(".csv").exists():
            out.append("%s: no %s beside it (every plotted series as CSV)" % (fig.relative_to(root), fig.with_suffix(".csv").name))
        if "figures/" + fig.name not in shown:
            out.append("%s: shown by no document (README.md, docs/*.md)" % fig.relative_to(root))
        if fig.name not in script:
            out.append("%s: not made by docs/figures/make_figures.sh" % fig.relative_to(root))
    return out


def self_test():
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        (root / "docs" / "figures").mkdir(parents=True)
        (root / "docs" / "figures" / "make_figures.sh").write_text("cp a docs/figures/good.svg\n")
        for name in ("good.svg", "good.csv", "lonely.svg"):
            (root / "docs" / "figures" / name).write_text("")
        (root / "docs" / "guide.md").write_text("![good](figures/good.svg)\n")
        found = problems(root)
        expected = ["no lonely.csv beside it", "lonely.svg: shown by no document", "lonely.svg: not made by"]
        missed = [e for e in expected if not any(e in p for p in found)]
        if missed or any("good" in p for p in found):
            print("self-test failed: found %s, missed %s" % (found, missed))
            return 1
    print("self-test: a figure without its CSV, not shown and not made is caught; a good one passes")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    found = problems(sys.argv[1])
    for p in found:
        print(p)
    n = len(list((pathlib.Path(sys.argv[1]) / "docs" / "figures").glob("*.[sp][vn]g")))
    print("%d figures, %d problems" % (n, len(found)))
    return 1 if found else 0


sys.exit(main())
