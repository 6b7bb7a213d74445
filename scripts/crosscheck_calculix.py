#!/usr/bin/python3
"""Cross-check pneufem against CalculiX on the identical mesh.

1. `pneufem mesh --out DIR/job.inp` writes the scene's mesh, materials, boundary conditions and
   cavity pressure as a CalculiX deck (one NLGEOM static step, step time = pressure in kPa).
2. CalculiX (ccx) solves it; displacements are read from DIR/job.frd at every load.step_kPa.
3. `pneufem simulate` runs the same scene (quasi-static staircase, one trial).
4. The bending angle is computed from the ccx displacements with an independent Python
   implementation of pneufem's definition (least-squares plane through the tip-face nodes,
   sign from the rigid best fit, half-model mirror, unwrapped), and both curves are tabulated
   with their wall times.

Needs Debian's python3-numpy (run with /usr/bin/python3) and a ccx binary. Stock ccx 2.20 stalls
near 6.5 kPa (its static tangent lacks the follower-pressure load stiffness); build the patched
one with bench/calculix/ccx_patch/build_ccx_patched.sh (tangent-only fix, bench/calculix/README.md).

usage: scripts/crosscheck_calculix.py [--ccx /tmp/ccx-2.20-patched/ccx] [--out bench/results/ccx_h2]
                                      [--set key=value ...] [--threads 2] [--reuse-ccx]
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_inp(path):
    """Nodes (id -> xyz) and the PNEUFEM_TIP node set of a deck written by `pneufem mesh`."""
    nodes, tip, block = {}, [], None
    with open(path) as fh:
        for line in fh:
            if line.startswith("*"):
                up = line.upper().replace(" ", "")
                block = "node" if up.startswith("*NODE") and "PRINT" not in up and "FILE" not in up else (
                    "tip" if up.startswith("*NSET,NSET=PNEUFEM_TIP") else None)
                continue
            if block == "node":
                p = line.split(",")
                nodes[int(p[0])] = np.array([float(p[1]), float(p[2]), float(p[3])])
            elif block == "tip":
                tip += [int(v) for v in line.replace(",", " ").split()]
    return nodes, tip


def read_frd(path, keep):
    """(time, {node: u}) for every DISP block of an ASCII .frd."""
    out, t = [], None
    with open(path) as fh:
        for line in fh:
            if line.startswith("  100C"):
                t = float(line[12:24])
            elif line.startswith(" -4  DISP"):
                u = {}
                for row in fh:
                    if row.startswith(" -3"):
                        break
                    if row.startswith(" -1"):
                        nid = int(row[3:13])
                        if nid in keep:
                            u[nid] = np.array([float(row[13:25]), float(row[25:37]), float(row[37:49])])
                out.append((t, u))
    return out


def bending_angle(X, x, half, n_fixed_out=np.array([0, -1.0, 0]), bend=np.array([0, 0, -1.0])):
    """pneufem's angle definition (engine/angle.h), independently implemented."""
    if half:  # mirror about x = 0 (nodes on the plane are not duplicated)
        off = np.abs(X[:, 0]) > 1e-9 * (1 + np.linalg.norm(X, axis=1))
        X = np.vstack([X, X[off] * [-1, 1, 1]])
        x = np.vstack([x, x[off] * [-1, 1, 1]])
    n0 = -n_fixed_out / np.linalg.norm(n_fixed_out)
    P, Q = X - X.mean(0), x - x.mean(0)
    N_ref = np.linalg.svd(P)[2][2]
    N_ref = N_ref if N_ref @ n0 > 0 else -N_ref
    U, S, Vt = np.linalg.svd(P.T @ Q)
    D = np.diag([1, 1, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    n = np.linalg.svd(Q)[2][2]
    n = n if n @ (R @ N_ref) > 0 else -n
    d = bend - (bend @ n0) * n0
    d /= np.linalg.norm(d)
    return np.degrees(np.arctan2(n @ d, n @ n0))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ccx", default=os.environ.get("CCX", "/tmp/ccx-2.20-patched/ccx"))
    ap.add_argument("--pneufem", default=os.path.join(ROOT, "build", "app", "pneufem"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "ccx_default"))
    ap.add_argument("--set", action="append", default=[], help="scene override, passed to both runs")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reuse-ccx", action="store_true", help="reuse an existing job.frd in --out (and its recorded wall time)")
    ap.add_argument("--ccx-only", action="store_true", help="run CalculiX only (pneufem later with --reuse-ccx)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    sets = sum([["--set", s] for s in a.set], [])
    deck = os.path.join(a.out, "job.inp")
    subprocess.run([a.pneufem, "mesh", "--out", deck] + sets, check=True)

    env = dict(os.environ, OMP_NUM_THREADS=str(a.threads), CCX_NPROC_EQUATION_SOLVER=str(a.threads))
    ccx_wall = None
    if not (a.reuse_ccx and os.path.exists(os.path.join(a.out, "job.frd"))):
        t0 = time.time()
        with open(os.path.join(a.out, "ccx.log"), "w") as log:
            subprocess.run([a.ccx, "-i", "job"], cwd=a.out, env=env, stdout=log, stderr=subprocess.STDOUT, check=False)
        ccx_wall = time.time() - t0
        with open(os.path.join(a.out, "ccx_wall_s.txt"), "w") as fh:
            fh.write(f"{ccx_wall:.1f}\n")
    elif os.path.exists(os.path.join(a.out, "ccx_wall_s.txt")):
        with open(os.path.join(a.out, "ccx_wall_s.txt")) as fh:
            ccx_wall = float(fh.read())  # the wall time of the run being reused

    if a.ccx_only:
        print(f"ccx wall time {ccx_wall:.1f} s" if ccx_wall is not None else "ccx: reused")
        return 0
    t0 = time.time()
    pf_out = os.path.join(a.out, "pneufem")
    subprocess.run([a.pneufem, "simulate", "--out", pf_out, "--threads", str(a.threads),
                    "--set", "output.vtu=\"none\""] + sets, check=True)
    pf_wall = time.time() - t0
    pf = {}
    with open(os.path.join(pf_out, "angles.csv")) as fh:
        next(fh)
        for line in fh:
            tr, t, p, ang = line.split(",")
            pf[round(float(p), 6)] = float(ang)  # last report of each level = end of its hold

    nodes, tip = read_inp(deck)
    X = np.array([nodes[n] for n in tip])
    half = X[:, 0].min() > -1e-9
    ccx = {}
    prev = 0.0
    for t, u in read_frd(os.path.join(a.out, "job.frd"), set(tip)):
        x = X + np.array([u[n] for n in tip])
        ang = bending_angle(X, x, half)
        ang += 360.0 * round((prev - ang) / 360.0)
        prev = ang
        ccx[round(t, 6)] = ang

    rows = []
    print(f"{'p_kPa':>6} {'ccx_deg':>9} {'pneufem_deg':>11} {'rel_diff_%':>10}")
    for p in sorted(pf):
        if p == 0:
            continue
        c = ccx.get(p)
        d = 100.0 * (pf[p] - c) / c if c else float("nan")
        rows.append({"p_kPa": p, "ccx_deg": c, "pneufem_deg": pf[p], "rel_diff_pct": d})
        print(f"{p:6.1f} {c if c is not None else float('nan'):9.3f} {pf[p]:11.3f} {d:10.2f}")
    summary = json.load(open(os.path.join(pf_out, "summary.json")))
    result = {"sets": a.set, "ccx_wall_s": ccx_wall, "pneufem_wall_s": pf_wall, "rows": rows,
              "mesh": summary["mesh"], "pneufem_solver": summary["solver"], "threads": a.threads}
    with open(os.path.join(a.out, "crosscheck.json"), "w") as fh:
        json.dump(result, fh, indent=1)
    print(f"wall time: ccx {ccx_wall if ccx_wall is not None else float('nan'):.1f} s, pneufem {pf_wall:.1f} s")


if __name__ == "__main__":
    sys.exit(main())
