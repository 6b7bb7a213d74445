#!/usr/bin/python3
"""Recordings with a hidden effect, made WITHOUT pneufem (needs Debian's python3-numpy).

The elastic angle curve theta_e(p) is CalculiX's static NLGEOM solution of a gmsh-meshed pneu-net
(tests/data/ccx_gmsh/ccx_angles.csv: 1 kPa outputs, plane-fit angle), interpolated by a monotone
cubic (Fritsch-Carlson). The hidden effects are phenomenological laws written here, in the angle
and the pressure, independent of pneufem's constitutive models:

  none      theta = theta_e(p)
  stiffness theta = CalculiX on the same deck with every silicone constant x1.25 (--stiff CSV;
            ccx_angles_stiff125.csv here, 0-50 kPa)
  lag       the chamber pressure follows the inlet through a first-order lag (tau 1.0 s)
  The history effects act through an effective load, theta = theta_e(p_eff): scaling every
  modulus of a structure by s deforms it as the load p/s would (exact for a homogeneous material,
  close here: the fabric does not scale but hardly stretches), so a softening in time is a rise of
  p_eff and is amplified near the limit point, as in a real actuator.
  creep     quasi-linear viscoelasticity (Fung) in the load: p_eff = integral c(t - s) dp(s),
            c(t) = 1 - g exp(-t/tau), g = 0.08, tau = 6 s (instantaneous response stiffer by
            1/(1 - g), long-term = the CalculiX curve)
  softening trials >= 2: p_eff = p (1 + a (1 - (p/p_max)^2)), a = 0.04, p_max = the highest
            pressure of the earlier trials (Mullins-like: softer below the previous maximum)
  wear      a global damage D, dD/dt = k <(p - 30 kPa)/15 kPa>^2, k = 0.0005 1/s, never healing;
            p_eff = p (1 + D) (grows during the top holds and over trials)

The inlet pressure is a staircase 0 -> 45 kPa in 5 kPa steps (hold 10 s, three trials, 20 s rest),
commanded through a second-order regulator (1.5 Hz, damping 0.8), sampled at 100 Hz with 0.08 kPa
noise; the angle at 30 fps with 0.08 deg noise and 0.3 % outlier frames (tracking glitches).
"""
import argparse
import csv
import json
import os

import numpy as np


def pchip(x, y):
    """Monotone cubic interpolant (Fritsch-Carlson) of samples y(x), x increasing."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    h = np.diff(x)
    d = np.diff(y) / h
    m = np.zeros_like(y)
    m[0], m[-1] = d[0], d[-1]
    for i in range(1, len(y) - 1):
        if d[i - 1] * d[i] > 0:
            w1, w2 = 2 * h[i] + h[i - 1], h[i] + 2 * h[i - 1]
            m[i] = (w1 + w2) / (w1 / d[i - 1] + w2 / d[i])

    def f(q):
        q = np.clip(np.asarray(q, float), x[0], x[-1])
        i = np.clip(np.searchsorted(x, q) - 1, 0, len(x) - 2)
        t = (q - x[i]) / h[i]
        h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
        h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
        return h00 * y[i] + h10 * h[i] * m[i] + h01 * y[i + 1] + h11 * h[i] * m[i + 1]

    return f


def curve(path):
    rows = list(csv.DictReader(open(path)))
    p = [float(r["pressure_kPa"]) for r in rows]
    a = [float(r.get("angle_planefit_deg", r.get("angle_deg"))) for r in rows]
    return pchip(p, a)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elastic", required=True, help="CalculiX curve (pressure_kPa, angle_planefit_deg)")
    ap.add_argument("--stiff", help="CalculiX curve of the stiffer material (for 'stiffness')")
    ap.add_argument("--effect", required=True,
                    choices=["none", "stiffness", "lag", "creep", "softening", "wear"])
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--trials", type=int, default=3)
    ap.add_argument("--hold", type=float, default=10.0)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    theta_e = curve(a.elastic)
    if a.effect == "stiffness":
        theta_e = curve(a.stiff)

    levels = np.arange(0.0, 45.0 + 1e-9, 5.0)
    dt = 0.01  # s, pressure sampling and integration step
    rest = 20.0
    # commanded staircase per trial, then the regulator (x'' = w^2 (u - x) - 2 z w x')
    wn, zeta = 2 * np.pi * 1.5, 0.8
    rows_p, rows_a = [], []
    truth = []
    D = 0.0  # wear damage, carried over trials
    h_state = 0.0  # creep state (kPa)
    p_prev_max = 1e-9  # highest pressure of the earlier trials (kPa)
    p_end = 0.0  # pressure at the end of the previous trial (kPa)
    for trial in range(1, a.trials + 1):
        T = len(levels) * a.hold
        n = int(round(T / dt)) + 1
        t = np.arange(n) * dt
        u = levels[np.minimum((t // a.hold).astype(int), len(levels) - 1)]
        x = np.zeros(n)
        xd = 0.0
        for i in range(1, n):
            acc = wn * wn * (u[i - 1] - x[i - 1]) - 2 * zeta * wn * xd
            xd += acc * dt
            x[i] = x[i - 1] + xd * dt
        p_in = x  # the true inlet pressure (what the sensor reads)
        p_ch = p_in.copy()
        if a.effect == "lag":
            tau = 1.0
            for i in range(1, n):
                p_ch[i] = p_ch[i - 1] + (p_in[i] - p_ch[i - 1]) * (1 - np.exp(-dt / tau))
        p_eff = np.maximum(p_ch, 0.0)
        if a.effect == "creep":
            g, tau = 0.08, 6.0
            # c(t) = 1 - g e^{-t/tau}: p_eff = p - g h, h' = (dp/dt) - h/tau (h carries over trials)
            # the vent to 0 after the previous trial (a load step -p_end), then the rest
            h_state = (h_state - p_end) * np.exp(-rest / tau) if trial > 1 else 0.0
            out = np.zeros(n)
            for i in range(n):
                dp = p_eff[i] - (p_eff[i - 1] if i > 0 else 0.0)
                h_state = h_state * np.exp(-dt / tau) + dp
                out[i] = p_eff[i] - g * h_state
            p_eff = out
        elif a.effect == "softening" and trial >= 2:
            p_eff = p_eff * (1 + 0.04 * (1 - np.minimum(p_eff / p_prev_max, 1.0) ** 2))
        elif a.effect == "wear":
            out = np.zeros(n)
            for i in range(n):
                D += 0.0005 * max(0.0, (p_ch[i] - 30.0) / 15.0) ** 2 * dt
                out[i] = p_eff[i] * (1 + D)
            p_eff = out
        p_prev_max = max(p_prev_max, float(np.max(p_ch)))
        p_end = float(max(p_ch[-1], 0.0))
        th = theta_e(p_eff)
        frames = np.arange(0.0, T, 1 / 30.0)
        th_f = np.interp(frames, t, th)
        for i in range(n):
            rows_p.append((trial, t[i], p_in[i] + rng.normal(0, 0.08)))
        for k, tf in enumerate(frames):
            ang = th_f[k] + rng.normal(0, 0.08)
            if rng.random() < 0.003:
                ang += rng.choice([-1, 1]) * rng.uniform(10, 30)
            rows_a.append((trial, tf, ang))
            truth.append((trial, tf, float(np.interp(tf, t, p_in)), th_f[k]))
    # one canonical file: pressure rows (angle empty) and frame rows (pressure empty), by time
    allrows = [(tr, tm, f"{pv:.4f}", "") for tr, tm, pv in rows_p] + \
              [(tr, tm, "", f"{av:.4f}") for tr, tm, av in rows_a]
    allrows.sort(key=lambda r: (r[0], r[1]))
    with open(a.out, "w") as f:
        f.write("trial,time_s,pressure_kPa,angle_deg\n")
        for tr, tm, pv, av in allrows:
            f.write(f"{tr},{tm:.4f},{pv},{av}\n")
    base = os.path.splitext(a.out)[0]
    with open(base + ".truth.csv", "w") as f:
        f.write("trial,time_s,pressure_kPa,angle_deg\n")
        for r in truth:
            f.write("%d,%.4f,%.5f,%.5f\n" % r)
    json.dump({"effect": a.effect, "seed": a.seed, "trials": a.trials, "hold_s": a.hold,
               "wear_damage_end": D}, open(base + ".truth.json", "w"), indent=1)


if __name__ == "__main__":
    main()
