"""viz/paraview/open_run.py run for real, in ParaView's pvbatch, on a tiny `pneufem simulate`.

The user guide's ParaView step as a newcomer runs it: the script opens the run's results.pvd, warps,
mirrors and colours it, charts angles.csv and saves views.png. Checks that pvbatch exits cleanly, that
nothing it printed is a Python traceback or a VTK/ParaView error, and that views.png is a PNG of the
size the script asks for (1600 x 1000) with a picture in it (not one flat colour). ParaView is not a
dependency of pneufem: without pvbatch, or with one that cannot import paraview.simple, the test is
skipped (exit 77, ctest's SKIP_RETURN_CODE) and says how to get it (scripts/install-paraview.sh). Debian's ParaView renders through X only: without
a DISPLAY it runs under xvfb-run (around the wrapper of install-paraview.sh too, which then sees one).
tests/viz/paraview/test_open_run.py checks the same script's arrays without ParaView.

    /usr/bin/python3 tests/viz/paraview/test_open_run_pvbatch.py PNEUFEM_EXE WORK_DIR [PVBATCH]
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SCRIPT = os.path.join(REPO, "viz", "paraview", "open_run.py")
TINY = ["--set", "geometry.chambers=2", "--set", "mesh.h_mm=6.0", "--set", "load.max_kPa=5.0", "--set", "load.trials=1"]
SKIP = 77
# Lines of pvbatch's output that mean the script did not do its work.
FAILURE = re.compile(r"Traceback|Error:|\bERR\||FATL|Segmentation|Aborted")


def skip(why):
    print("SKIPPED: " + why + " (scripts/install-paraview.sh installs ParaView on Debian 12)")
    sys.exit(SKIP)


def pvbatch_command(pvbatch):
    """pvbatch, under a virtual X server when there is no display and xvfb-run is at hand."""
    if os.environ.get("DISPLAY"):
        return [pvbatch]
    xvfb = shutil.which("xvfb-run")
    if xvfb:
        return [xvfb, "-a", "-s", "-screen 0 1920x1080x24", pvbatch]
    return [pvbatch, "--force-offscreen-rendering"]  # a ParaView built for offscreen rendering (EGL, OSMesa)


def png_pixels(path):
    """Width, height and the distinct RGB(A) pixel values of a PNG (8-bit, no interlace), standard library only."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "%s is not a PNG" % path
    pos, chunks = 8, {}
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunks.setdefault(kind, []).append(data[pos + 8:pos + 8 + n])
        pos += 12 + n
    width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks[b"IHDR"][0])
    assert depth == 8 and colour in (2, 6) and interlace == 0, "unexpected PNG format %d/%d/%d" % (depth, colour, interlace)
    bpp = 3 if colour == 2 else 4
    raw = zlib.decompress(b"".join(chunks[b"IDAT"]))
    stride = width * bpp
    prev, colours = bytearray(stride), set()
    for row in range(height):
        f, line = raw[row * (stride + 1)], bytearray(raw[row * (stride + 1) + 1:(row + 1) * (stride + 1)])
        for i in range(stride):  # undo the row filter (PNG spec, sec. 9)
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        if row % 10 == 0:
            colours.update(bytes(line[i:i + bpp]) for i in range(0, stride, bpp * 10))
        prev = line
    return width, height, colours


def main():
    exe, work = sys.argv[1], sys.argv[2]
    pvbatch = sys.argv[3] if len(sys.argv) > 3 and sys.argv[3] and not sys.argv[3].endswith("NOTFOUND") else shutil.which("pvbatch")
    if not pvbatch:
        skip("pvbatch not found")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    run = os.path.join(work, "run")
    subprocess.run([exe, "simulate", "--threads", "1", "--out", run] + TINY, check=True, stdout=subprocess.DEVNULL)
    command = pvbatch_command(pvbatch) + [SCRIPT, run]
    for attempt in range(3):  # xvfb-run -a can lose the race for a display number ("bad X server connection")
        p = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=240)
        if "bad X server connection" not in p.stdout:
            break
        print("pvbatch found no X server (attempt %d); again" % (attempt + 1))
    print(" ".join(command))
    print(p.stdout)
    if "No module named 'paraview'" in p.stdout:
        skip("%s cannot import paraview.simple (Debian's paraview without python3-paraview)" % pvbatch)
    assert p.returncode == 0, "pvbatch exited with %d" % p.returncode
    bad = [line for line in p.stdout.splitlines() if FAILURE.search(line)]
    assert not bad, "pvbatch printed errors:\n" + "\n".join(bad)
    png = os.path.join(run, "views.png")
    assert os.path.exists(png), "no views.png in " + run
    width, height, colours = png_pixels(png)
    assert (width, height) == (1600, 1000), "views.png is %dx%d, the script asks for 1600x1000" % (width, height)
    assert len(colours) > 50, "views.png has %d colours: an empty picture" % len(colours)
    print("views.png: %dx%d, %d colours in a sample" % (width, height, len(colours)))


main()
