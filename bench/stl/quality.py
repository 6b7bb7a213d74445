#!/usr/bin/env python3
"""Tetrahedron quality of the STL mesher against gmsh on the same STL (issue 33 item 3).

Both meshes' corner tetrahedra are measured by the same code here: the smallest dihedral angle
of each element (10-degree bins, as pneufem's mesh report) and the normalised radius ratio
3 r_in / r_circ (1 = regular; 0.1 bins; the definition of engine/mesh.cpp compute_stats).

    /usr/bin/python3 bench/stl/quality.py --pneufem build/app/pneufem --stl model.stl --h 1.5 \
        [--set mesh.feature_planes=false ...]

gmsh (4.8, Debian's python3-gmsh) meshes the STL as in its tutorial t13: the triangles are
classified into patches (40 degrees), a geometry is built on them and the volume bounded by all
of them is meshed by its Delaunay mesher with the element size h; pneufem runs
`pneufem mesh STL --out tmp.inp --set mesh.h_mm=h --set mesh.half=false`.
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

PAIRS = [(0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2), (1, 2, 0, 3), (1, 3, 0, 2), (2, 3, 0, 1)]


def min_dihedral_deg(P):
    """P: (n, 4, 3) corner coordinates -> (n,) smallest dihedral angle (degrees)."""
    lo = np.full(P.shape[0], 180.0)
    for i, j, k, l in PAIRS:
        e = P[:, j] - P[:, i]
        e /= np.linalg.norm(e, axis=1)[:, None]
        u = P[:, k] - P[:, i]
        w = P[:, l] - P[:, i]
        u -= (u * e).sum(1)[:, None] * e
        w -= (w * e).sum(1)[:, None] * e
        c = (u * w).sum(1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1))
        lo = np.minimum(lo, np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))
    return lo


def radius_ratio(P):
    a, b, c = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0], P[:, 3] - P[:, 0]
    V = np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0
    area = 0.0
    for f in ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)):
        area = area + 0.5 * np.linalg.norm(np.cross(P[:, f[1]] - P[:, f[0]], P[:, f[2]] - P[:, f[0]]), axis=1)
    num = (a * a).sum(1)[:, None] * np.cross(b, c) + (b * b).sum(1)[:, None] * np.cross(c, a) + (c * c).sum(1)[:, None] * np.cross(a, b)
    r_circ = np.linalg.norm(num, axis=1) / (12.0 * V + 1e-300)
    r_in = 3.0 * V / (area + 1e-300)
    return np.clip(3.0 * r_in / (r_circ + 1e-300), 0.0, 1.0)


def read_inp_tets(path):
    """Corner tetrahedra of a C3D10/C3D4 deck (pneufem writes mm): (n, 4, 3)."""
    nodes, tets, mode = {}, [], None
    with open(path) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("**"):
                continue
            if s.startswith("*"):
                key = s.upper().replace(" ", "")
                mode = "node" if re.match(r"\*NODE(,|$)", key) else ("el" if re.match(r"\*ELEMENT(,|$)", key) else None)
                pending = []
                continue
            if mode == "node":
                v = s.split(",")
                nodes[int(v[0])] = [float(x) for x in v[1:4]]
            elif mode == "el":
                v = [x for x in s.split(",") if x.strip()]
                pending += [int(x) for x in v]
                if len(pending) >= 5:  # id + at least 4 corners (C3D10 may continue on a second line)
                    if s.endswith(","):
                        continue
                    tets.append(pending[1:5])
                    pending = []
    X = np.array([nodes[i] for t in tets for i in t]).reshape(-1, 4, 3)
    return X


def pneufem_mesh(exe, stl, h, sets):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "m.inp")
        cmd = [exe, "mesh", stl, "--out", out, "--set", f"mesh.h_mm={h}", "--set", "mesh.half=false"]
        for s in sets:
            cmd += ["--set", s]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"pneufem mesh failed ({r.returncode}): {r.stderr}{r.stdout}")
        return read_inp_tets(out)


def gmsh_mesh(stl, h_mm):
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.merge(stl)
    gmsh.model.mesh.classifySurfaces(40 * math.pi / 180, True, True, math.pi)
    gmsh.model.mesh.createGeometry()
    surfaces = [e[1] for e in gmsh.model.getEntities(2)]
    loop = gmsh.model.geo.addSurfaceLoop(surfaces)
    gmsh.model.geo.addVolume([loop])
    gmsh.model.geo.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", h_mm)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h_mm)
    gmsh.model.mesh.generate(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    pos = {int(t): coords[3 * i:3 * i + 3] for i, t in enumerate(tags)}
    _, el_nodes = gmsh.model.mesh.getElementsByType(4)
    conn = np.array(el_nodes, dtype=np.int64).reshape(-1, 4)
    gmsh.finalize()
    return np.array([[pos[int(n)] for n in t] for t in conn])  # mm, as the STL


PERCENT = False


def bins(h):
    """Counts, or with --percent each bin's share of the elements (%), so meshes of different sizes compare."""
    if not PERCENT:
        return " ".join(str(c) for c in h)
    return " ".join(f"{100.0 * c / max(h.sum(), 1):.1f}" for c in h)


def summary(name, P):
    dih, rr = min_dihedral_deg(P), radius_ratio(P)
    vol = np.abs(np.einsum("ij,ij->i", P[:, 1] - P[:, 0], np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 0]))).sum() / 6.0
    hd = np.histogram(dih, bins=np.arange(0, 190, 10))[0]
    hr = np.histogram(rr, bins=np.linspace(0, 1, 11))[0]
    print(f"| {name} | {len(P)} | {vol:.1f} | {dih.min():.1f} / {np.percentile(dih, 1):.1f} | "
          f"{rr.min():.3f} / {rr.mean():.3f} | {bins(hd[:9])} | {bins(hr)} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pneufem", required=True)
    ap.add_argument("--stl", required=True, help="in mm")
    ap.add_argument("--h", type=float, required=True, help="element size, mm")
    ap.add_argument("--set", action="append", default=[], help="a scene key for pneufem mesh")
    ap.add_argument("--no-gmsh", action="store_true")
    ap.add_argument("--percent", action="store_true", help="histograms as shares of the elements (%%)")
    a = ap.parse_args()
    global PERCENT
    PERCENT = a.percent
    print("| mesher | tets | volume mm^3 | min dihedral: smallest / 1st percentile (deg) | radius ratio min / mean "
          "| elements by smallest dihedral, 10-deg bins 0-90 | by radius ratio, 0.1 bins 0-1 |")
    print("|---|---|---|---|---|---|---|")
    summary(f"pneufem h={a.h} {' '.join(a.set)}", pneufem_mesh(a.pneufem, a.stl, a.h, a.set))
    if not a.no_gmsh:
        summary(f"gmsh {gmsh_version()} h={a.h}", gmsh_mesh(a.stl, a.h))


def gmsh_version():
    import gmsh
    return gmsh.__version__


if __name__ == "__main__":
    main()
