#!/usr/bin/env python3
"""The built-in pneu-net (scenes/pneunet.h) written as a closed binary STL in mm (issue 33 item 3).

The same surface as the test helper tests/scenes/stl/test_shapes.h `pneunet_surface`: the faces
between solid and void cells of the grid through the actuator's feature planes, two triangles per
face, so the triangulation is watertight and has no T-junctions. The fabric layer is not in the
STL (it is a slab of the solid: `mesh.fabric_slab_mm`, default [1.8, 2.2]).

    /usr/bin/python3 bench/stl/pneunet_stl.py OUT.stl [--chambers 15] [--length-scale 1]

Every dimension is the built-in default unless given (mm).
"""
import argparse
import struct


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--width", type=float, default=22.0)
    ap.add_argument("--base", type=float, default=3.0)
    ap.add_argument("--body", type=float, default=15.0)
    ap.add_argument("--chambers", type=int, default=15)
    ap.add_argument("--chamber-length", type=float, default=6.0)
    ap.add_argument("--wall", type=float, default=2.0)
    ap.add_argument("--side", type=float, default=7.0)
    ap.add_argument("--roof", type=float, default=7.0)
    ap.add_argument("--cap", type=float, default=4.0)
    ap.add_argument("--channel-width", type=float, default=2.0)
    ap.add_argument("--channel-height", type=float, default=2.0)
    a = ap.parse_args()

    hw, hc, hch = 0.5 * a.width, 0.5 * a.width - a.side, 0.5 * a.channel_width
    hb, top = a.base, a.base + a.body
    L = 2 * a.cap + a.chambers * a.chamber_length + (a.chambers - 1) * a.wall
    y0 = [a.cap + i * (a.chamber_length + a.wall) for i in range(a.chambers)]
    lines = [[-hw, -hc, -hch, hch, hc, hw], [0.0], [0.0, hb, hb + a.channel_height, top - a.roof, top]]
    for y in y0:
        lines[1] += [y, y + a.chamber_length]
    lines[1].append(L)
    n = [len(l) for l in lines]

    def solid(x):
        for y in y0:
            if abs(x[0]) < hc and y < x[1] < y + a.chamber_length and hb < x[2] < top - a.roof:
                return False
        if abs(x[0]) < hch and y0[0] < x[1] < y0[-1] + a.chamber_length and hb < x[2] < hb + a.channel_height:
            return False
        return True

    def inside(c):
        if any(c[d] < 0 or c[d] >= n[d] - 1 for d in range(3)):
            return False
        return solid([0.5 * (lines[d][c[d]] + lines[d][c[d] + 1]) for d in range(3)])

    tris = []
    for i in range(-1, n[0]):
        for j in range(-1, n[1]):
            for k in range(-1, n[2]):
                for d in range(3):
                    c = [i, j, k]
                    nb = list(c)
                    nb[d] += 1
                    sa, sb = inside(c), inside(nb)
                    if sa == sb:
                        continue
                    u, w = (d + 1) % 3, (d + 2) % 3
                    if c[u] < 0 or c[w] < 0 or c[u] + 1 >= n[u] or c[w] + 1 >= n[w] or nb[d] < 0 or nb[d] >= n[d]:
                        continue
                    p = [list(nb) for _ in range(4)]
                    p[1][u] += 1
                    p[2][u] += 1
                    p[2][w] += 1
                    p[3][w] += 1
                    q = [tuple(lines[e][g[e]] for e in range(3)) for g in p]
                    # (u, w, d) right-handed: q0 q1 q2 counter-clockwise seen from +d, outward if c is solid.
                    if sa:
                        tris += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
                    else:
                        tris += [(q[0], q[2], q[1]), (q[0], q[3], q[2])]

    with open(a.out, "wb") as f:
        f.write(b"pneufem pneu-net, mm".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            e1 = [t[1][m] - t[0][m] for m in range(3)]
            e2 = [t[2][m] - t[0][m] for m in range(3)]
            nrm = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            s = sum(v * v for v in nrm) ** 0.5 or 1.0
            f.write(struct.pack("<3f", *[v / s for v in nrm]))
            for v in t:
                f.write(struct.pack("<3f", *v))
            f.write(b"\0\0")
    print(f"{a.out}: {len(tris)} triangles, {a.chambers} chambers, length {L:g} mm")


if __name__ == "__main__":
    main()
