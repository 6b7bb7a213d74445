#!/usr/bin/env python3
"""The bending angle of a run's state, from its VTU, two ways (issue 33 item 3).

pneufem's angle (engine/angle.h) is the rotation of the least-squares plane through the TIP
nodes, every node weighted alike. A cut mesh puts many more nodes near the tip face's edges than
a grid does, and at small angles the tip face warps by as much as it turns (tip_plane_rms in
states.csv), so the node-weighted plane depends on where the nodes are. Weighting each node by
its share of the face's area (the 3 mid-edge nodes of each quadratic tip triangle, a third of its
area each: the midpoint rule, exact for the plane's linear moments) gives the plane of the
continuous face, the same for any mesh of it.

    /usr/bin/python3 bench/stl/tip_angle.py RUN/vtu/state_0001.vtu ...

Prints, per file, the angle in the y-z plane (fixed face y = 0, the tip the largest y) by nodes
and by area. Needs VTK's Python module (Debian's python3-vtk9).
"""
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

# Quadratic tetrahedron faces: 3 corners, then the 3 mid-edge nodes (VTK's node order).
FACES = [(0, 1, 2, 4, 5, 6), (0, 1, 3, 4, 8, 7), (1, 2, 3, 5, 9, 8), (0, 2, 3, 6, 9, 7)]


def load(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    X = vtk_to_numpy(g.GetPoints().GetData()).astype(float)
    U = vtk_to_numpy(g.GetPointData().GetArray("displacement_m")).astype(float)
    conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 10)
    return X, U, conn


def plane_angle_deg(P, w):
    c = (w[:, None] * P).sum(0) / w.sum()
    n = np.linalg.svd((P - c) * np.sqrt(w)[:, None], full_matrices=False)[2][-1]
    if n[1] < 0:
        n = -n
    return np.degrees(np.arctan2(-n[2], n[1]))


def main():
    for path in sys.argv[1:]:
        X, U, conn = load(path)  # X: reference coordinates (m)
        L = X[:, 1].max()
        on_tip = np.abs(X[:, 1] - L) < 1e-9
        tip = np.where(on_tip)[0]
        by_nodes = plane_angle_deg(X[tip] + U[tip], np.ones(len(tip)))
        pts, wts = [], []
        for c in conn:
            for f in FACES:
                if on_tip[c[list(f[:3])]].all():
                    a = 0.5 * np.linalg.norm(np.cross(X[c[f[1]]] - X[c[f[0]]], X[c[f[2]]] - X[c[f[0]]]))
                    for k in f[3:]:
                        pts.append(X[c[k]] + U[c[k]])
                        wts.append(a / 3.0)
        by_area = plane_angle_deg(np.array(pts), np.array(wts))
        print(f"{path}: {len(tip)} tip nodes; angle by nodes {by_nodes:.6f} deg, by area {by_area:.6f} deg")


if __name__ == "__main__":
    main()
