#!/usr/bin/env python3
"""Recordings made by other means than pneufem's laws (issue 35, items 4 and 5).

Each recording starts from an ELASTIC angle-vs-pressure curve of the small actuator
(scenes/examples/small_actuator.toml: 5 chambers, h = 6 mm), a static curve in curves/ made once
with `pneufem simulate` (see README.md), and applies hidden effects AT THE STRUCTURE LEVEL, in
forms that are not pneufem's constitutive laws:

  creep      Fung's quasi-linear viscoelasticity in creep form on the elastic ANGLE:
               theta(t) = theta_e(p(t)) + integral dJ(t - s) d theta_e(p(s)),
             with a stretched-exponential (Kohlrausch) creep function dJ = g (1 - exp(-(t/tau)^beta))
             or a power law dJ = a (t/t0)^n; dJ(0) = 0, so the elastic curve is the INSTANTANEOUS
             response and the angle creeps above it (Abaqus's MODULI=INSTANTANEOUS convention).
  fatigue    a compliance growth with a load-weighted cycle count N(t) = int (p/p_ref)^m dt / T_ref
             (one trial at the reference peak ~ one cycle, Basquin-like weighting), as a power law
             D = a N^b or a log law D = a ln(1 + N / N0); theta = theta_e((1 + D) p).
  mullins    reload below the previous peak pressure p_max follows a softer curve:
               theta = theta_e(p (1 + A (1 - p/p_max)^k)) for p < p_max, theta_e(p) on the primary path.
  lag        the chamber pressure behind the inlet sensor: first order (tau) or second order
             under-damped (f_n, zeta); the recording holds the INLET pressure.
  static     a stiffness error theta_e(k p), another mesh's curve, another geometry's curve.

The rig: commanded staircase -> inlet regulator (second order, f_n, zeta: overshoot) -> sensor
(white noise, sampled at the pressure rate); angle from video at the frame rate with white tracking
noise and outlier frames (a tracking failure: +-[10, 40] deg). Trials follow each other without an
unrecorded gap; each trial starts at 0 kPa and its last step releases the pressure to 0 if the
protocol says so (else the release happens at the start of the next trial, as pneufem assumes).

Writes <name>.csv (trial,time_s,pressure_kPa,angle_deg, the canonical format of
analysis/measurements.h: pressure rows and angle rows interleaved by time) and <name>.truth.json.
Usage: /usr/bin/python3 tests/data/othermeans/make_recordings.py [names...]   (numpy only; seconds)
"""
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DT = 0.002  # simulation step of the rig and the structure (s)


def load_curve(name, here=None):
    """Static curve (pressure kPa, angle deg): curves/NAME.csv, from a `pneufem simulate` sweep."""
    d = np.genfromtxt(os.path.join(here or HERE, "curves", name + ".csv"), delimiter=",", names=True)
    p, a = d["pressure_kPa"], d["angle_deg"]
    _, idx = np.unique(p, return_index=True)
    return p[idx], a[idx]


class Elastic:
    """theta_e(p): monotone cubic (PCHIP-like, Fritsch-Carlson) through the curve's points."""

    def __init__(self, p, a):
        self.p, self.a = p, a
        d = np.diff(a) / np.diff(p)
        m = np.zeros_like(a)
        m[0], m[-1] = d[0], d[-1]
        for k in range(1, len(a) - 1):
            if d[k - 1] * d[k] > 0:
                m[k] = 2.0 / (1.0 / d[k - 1] + 1.0 / d[k])
        self.m = m

    def __call__(self, x):
        x = np.clip(np.asarray(x, dtype=float), self.p[0], self.p[-1])
        k = np.clip(np.searchsorted(self.p, x, side="right") - 1, 0, len(self.p) - 2)
        h = self.p[k + 1] - self.p[k]
        t = (x - self.p[k]) / h
        return ((2 * t**3 - 3 * t**2 + 1) * self.a[k] + (t**3 - 2 * t**2 + t) * h * self.m[k]
                + (-2 * t**3 + 3 * t**2) * self.a[k + 1] + (t**3 - t**2) * h * self.m[k + 1])


def commanded(protocol):
    """Commanded inlet pressure per trial: list of (levels, hold_s, release) -> t, u, trial index."""
    ts, us, trial = [], [], []
    t0 = 0.0
    for k, tr in enumerate(protocol["trials"]):
        levels = list(tr["levels"])
        hold = tr["hold_s"]
        if tr.get("release", False):
            levels.append(0.0)
        n = int(round(len(levels) * hold / DT))
        t = np.arange(n) * DT
        u = np.array([levels[min(int(ti / hold + 1e-9), len(levels) - 1)] for ti in t])
        ts.append(t + t0)
        us.append(u)
        trial.append(np.full(n, k))
        t0 += n * DT
    return np.concatenate(ts), np.concatenate(us), np.concatenate(trial)


def second_order(u, fn, zeta, x0=0.0):
    """x'' + 2 zeta w x' + w^2 (x - u) = 0, semi-implicit Euler at DT."""
    w = 2 * math.pi * fn
    x, v = x0, 0.0
    out = np.empty_like(u)
    for i, ui in enumerate(u):
        v += (w * w * (ui - x) - 2 * zeta * w * v) * DT
        x += v * DT
        out[i] = x
    return out


def first_order(u, tau):
    a = 1.0 - math.exp(-DT / tau)
    x = 0.0
    out = np.empty_like(u)
    for i, ui in enumerate(u):
        x += (ui - x) * a
        out[i] = x
    return out


def creep_function(spec, lags):
    if spec["form"] == "stretched_exponential":
        return spec["g"] * (1.0 - np.exp(-np.power(lags / spec["tau_s"], spec["beta"])))
    if spec["form"] == "power_law":
        return spec["a"] * np.power(lags / spec["t0_s"], spec["n"])
    raise ValueError(spec["form"])


def structure(t, pc, theta_e, effects, p_ref):
    """The angle of the structure under chamber pressure pc(t) with the hidden effects."""
    q = pc.copy()  # effective pressure into the elastic curve
    if "mullins" in effects:
        s = effects["mullins"]
        pmax = np.maximum.accumulate(np.maximum(pc, 0.0))
        below = pc < pmax
        ratio = np.where(pmax > 0, np.clip(pc, 0, None) / np.where(pmax > 0, pmax, 1.0), 1.0)
        q = np.where(below, pc * (1.0 + s["A"] * np.power(1.0 - ratio, s["k"])), pc)
    if "fatigue" in effects:
        s = effects["fatigue"]
        rate = np.power(np.clip(pc, 0, None) / p_ref, s["m"]) / s["T_ref_s"]
        N = np.cumsum(rate) * DT
        if s["form"] == "power_law":
            D = s["a"] * np.power(N, s["b"])
        elif s["form"] == "log":
            D = s["a"] * np.log1p(N / s["N0"])
        else:
            raise ValueError(s["form"])
        q = q * (1.0 + D)
    theta = theta_e(q)
    if "creep" in effects:
        # Fung QLV in creep form: the creep function acting on the elastic angle's increments,
        # a linear convolution (by FFT: the record is 10^5 steps).
        d_theta = np.diff(theta, prepend=0.0)
        lags = np.arange(len(t)) * DT
        J = creep_function(effects["creep"], lags)
        n = 1 << int(math.ceil(math.log2(2 * len(t))))
        extra = np.fft.irfft(np.fft.rfft(d_theta, n) * np.fft.rfft(J, n), n)[: len(t)]
        theta = theta + extra
    return theta


def make(name, spec, curves=None):
    rng = np.random.default_rng(spec["seed"])
    p_curve, a_curve = load_curve(spec.get("curve", "small_h6"), curves)
    if "stiffness_error" in spec:  # theta_e(k p): a uniformly softer (k > 1) or stiffer silicone
        k = spec["stiffness_error"]
        theta_e_raw = Elastic(p_curve, a_curve)
        theta_e = lambda x, f=theta_e_raw, k=k: f(k * np.asarray(x))
    else:
        theta_e = Elastic(p_curve, a_curve)
    t, u, trial = commanded(spec["protocol"])
    rig = spec["rig"]
    p_in = second_order(u, rig["regulator_hz"], rig["regulator_zeta"])
    lag = spec["effects"].get("lag")
    if lag is None:
        pc = p_in
    elif lag["form"] == "first_order":
        pc = first_order(p_in, lag["tau_s"])
    elif lag["form"] == "second_order":
        pc = second_order(p_in, lag["f_n_hz"], lag["zeta"])
    else:
        raise ValueError(lag["form"])
    p_ref = max(max(tr["levels"]) for tr in spec["protocol"]["trials"])
    theta = structure(t, pc, theta_e, spec["effects"], p_ref)
    theta_elastic = theta_e(p_in)  # what an ideal elastic actuator with no lag would do

    rows = []  # (trial, time, pressure or None, angle or None)
    ntr = len(spec["protocol"]["trials"])
    n_out = 0
    for k in range(ntr):
        idx = np.nonzero(trial == k)[0]
        tk = t[idx] - t[idx[0]]
        dur = tk[-1]
        # pressure samples
        tp = np.arange(0.0, dur + 1e-12, 1.0 / rig["pressure_hz"])
        pp = np.interp(tp, tk, p_in[idx]) + rng.normal(0.0, rig["pressure_noise_kPa"], len(tp))
        for a, b in zip(tp, pp):
            rows.append((k + 1, a, b, None))
        ta = np.arange(0.0, dur + 1e-12, 1.0 / rig["angle_fps"])
        aa = np.interp(ta, tk, theta[idx]) + rng.normal(0.0, rig["angle_noise_deg"], len(ta))
        out = rng.random(len(ta)) < rig.get("outliers", 0.005)
        aa[out] += rng.choice([-1.0, 1.0], out.sum()) * rng.uniform(10.0, 40.0, out.sum())
        n_out += int(out.sum())
        for a, b in zip(ta, aa):
            rows.append((k + 1, a, None, b))
    rows.sort(key=lambda r: (r[0], r[1], r[2] is None))
    path = os.path.join(HERE, name + ".csv")
    with open(path, "w") as f:
        f.write("trial,time_s,pressure_kPa,angle_deg\n")
        for tr, ti, p, a in rows:
            f.write("%d,%.4f,%s,%s\n" % (tr, ti, "" if p is None else "%.4f" % p, "" if a is None else "%.5f" % a))
    # Size of each effect: the largest and rms departure of the true angle from the elastic one.
    dev = theta - theta_elastic
    truth = dict(spec)
    truth.update({
        "outlier_frames": n_out,
        "peak_elastic_angle_deg": float(theta_elastic.max()),
        "effect_size_deg": {"max_abs": float(np.abs(dev).max()), "rms": float(np.sqrt(np.mean(dev**2)))},
        "made_by": "tests/data/othermeans/make_recordings.py",
    })
    with open(os.path.join(HERE, name + ".truth.json"), "w") as f:
        json.dump(truth, f, indent=1, sort_keys=True)
    print("%-28s %2d trials %6.1f s, %6d rows, effect max %.3f deg rms %.3f deg (peak %.2f deg), %d outliers"
          % (name, ntr, t[-1], len(rows), np.abs(dev).max(), np.sqrt(np.mean(dev**2)), theta_elastic.max(), n_out))


def staircase(trials, peak, step, hold, release=False, peaks=None):
    out = []
    for k in range(trials):
        pk = peaks[k] if peaks else peak
        levels = list(np.arange(0.0, pk + 1e-9, step))
        out.append({"levels": [float(x) for x in levels], "hold_s": hold, "release": release})
    return {"trials": out}


RIG_A = {"regulator_hz": 1.0, "regulator_zeta": 0.65, "pressure_hz": 200, "pressure_noise_kPa": 0.1,
         "angle_fps": 30, "angle_noise_deg": 0.05, "outliers": 0.005}
RIG_B = {"regulator_hz": 1.5, "regulator_zeta": 0.8, "pressure_hz": 500, "pressure_noise_kPa": 0.08,
         "angle_fps": 30, "angle_noise_deg": 0.04, "outliers": 0.003}
RIG_C = {"regulator_hz": 0.8, "regulator_zeta": 0.55, "pressure_hz": 100, "pressure_noise_kPa": 0.15,
         "angle_fps": 30, "angle_noise_deg": 0.08, "outliers": 0.008}

KWW = {"form": "stretched_exponential", "g": 0.35, "tau_s": 1.5, "beta": 0.6}
POWER_CREEP = {"form": "power_law", "a": 0.12, "t0_s": 1.0, "n": 0.35}
FATIGUE_POWER = {"form": "power_law", "a": 0.03, "b": 0.5, "m": 3.0, "T_ref_s": 8.0}
FATIGUE_LOG = {"form": "log", "a": 0.03, "N0": 0.5, "m": 2.0, "T_ref_s": 8.0}
MULLINS = {"A": 0.25, "k": 1.0}

RECORDINGS = {
    # item 5: one effect each, in forms other than pneufem's
    "creep_kww": {"seed": 11, "rig": RIG_A, "protocol": staircase(3, 30, 10, 4.0),
                  "effects": {"creep": KWW}},
    "creep_powerlaw": {"seed": 12, "rig": RIG_B, "protocol": staircase(4, 35, 7, 3.0, release=True),
                       "effects": {"creep": POWER_CREEP}},
    "fatigue_powerlaw": {"seed": 13, "rig": RIG_C, "protocol": staircase(10, 30, 10, 2.0),
                         "effects": {"fatigue": FATIGUE_POWER}},
    "fatigue_log": {"seed": 14, "rig": RIG_A, "protocol": staircase(8, 25, 5, 1.5),
                    "effects": {"fatigue": FATIGUE_LOG}},
    "mullins_reload": {"seed": 15, "rig": RIG_B, "protocol": staircase(4, 30, 10, 3.0, peaks=[30, 20, 30, 25]),
                       "effects": {"mullins": MULLINS}},
    "lag_first_order": {"seed": 16, "rig": RIG_B, "protocol": staircase(3, 30, 10, 3.0),
                        "effects": {"lag": {"form": "first_order", "tau_s": 0.4}}},
    "lag_second_order": {"seed": 17, "rig": RIG_A, "protocol": staircase(3, 30, 7.5, 3.0, release=True),
                         "effects": {"lag": {"form": "second_order", "f_n_hz": 0.6, "zeta": 0.45}}},
    # two and three effects together
    "creep_fatigue": {"seed": 21, "rig": RIG_A, "protocol": staircase(10, 30, 10, 2.5),
                      "effects": {"creep": KWW, "fatigue": FATIGUE_POWER}},
    "mullins_lag": {"seed": 22, "rig": RIG_C, "protocol": staircase(3, 30, 10, 3.0, peaks=[30, 30, 20]),
                    "effects": {"mullins": MULLINS, "lag": {"form": "first_order", "tau_s": 0.35}}},
    "creep_fatigue_lag": {"seed": 23, "rig": RIG_B, "protocol": staircase(6, 30, 10, 3.0),
                          "effects": {"creep": POWER_CREEP, "fatigue": FATIGUE_LOG,
                                      "lag": {"form": "first_order", "tau_s": 0.3}}},
    # item 4: static misfit only (the null)
    "null_mesh_h4": {"seed": 31, "rig": RIG_A, "protocol": staircase(10, 30, 10, 2.0), "curve": "small_h4",
                     "effects": {}},
    "null_stiffness_2pc": {"seed": 32, "rig": RIG_B, "protocol": staircase(4, 35, 7, 3.0), "stiffness_error": 1.02,
                           "effects": {}},
    "null_stiffness_3pc_stiffer": {"seed": 33, "rig": RIG_C, "protocol": staircase(5, 25, 5, 2.0),
                                   "stiffness_error": 0.97, "effects": {}},
    "null_geometry_wall": {"seed": 34, "rig": RIG_A, "protocol": staircase(3, 30, 10, 4.0), "curve": "small_h6_wall2.2",
                           "effects": {}},
}


# The detection-limit series of docs/verification.md (not committed: `--detection DIR` writes them to
# DIR): one effect at a time, at growing sizes, on one protocol and rig (A: 0.05 deg tracking noise).
DETECTION_PROTOCOL = staircase(3, 30, 10, 3.0)
DETECTION = {}
for g in (0.01, 0.02, 0.05, 0.1):
    DETECTION["det_creep_g%g" % g] = {"effects": {"creep": dict(KWW, g=g)}}
for a in (0.0025, 0.005, 0.01, 0.02):
    DETECTION["det_fatigue_a%g" % a] = {"effects": {"fatigue": dict(FATIGUE_POWER, a=a)},
                                        "protocol": staircase(6, 30, 10, 3.0)}
for A in (0.05, 0.07, 0.1, 0.2):
    DETECTION["det_mullins_A%g" % A] = {"effects": {"mullins": dict(MULLINS, A=A)},
                                        "protocol": staircase(3, 30, 10, 3.0, peaks=[30, 20, 30])}
for tau in (0.02, 0.03, 0.05, 0.1, 0.2):
    DETECTION["det_lag_tau%g" % tau] = {"effects": {"lag": {"form": "first_order", "tau_s": tau}}}
for name, d in DETECTION.items():
    d.setdefault("protocol", DETECTION_PROTOCOL)
    d.update({"seed": 41, "rig": RIG_A})


def main(args):
    global HERE
    if args and args[0] == "--detection":
        out = args[1]
        os.makedirs(out, exist_ok=True)
        here, HERE = HERE, out
        for name in args[2:] or DETECTION:
            if not os.path.isabs(out):
                raise SystemExit("--detection DIR: an absolute path")
            make(name, DETECTION[name], curves=here)
        return
    for name in args or RECORDINGS:
        make(name, RECORDINGS[name])


if __name__ == "__main__":
    main(sys.argv[1:])
