#!/usr/bin/env python3
"""Which Prony spectrum shape follows a power-law creep? (bench/notes/2026-11-29-diag3.md)

A fit of the STRUCTURE-level creep function, not pneufem: the recording generator's own model
(tests/data/othermeans/make_recordings.py: Fung creep of the elastic angle, the rig's regulator and a
0.3 s lag) on the protocol of creep_fatigue_lag.csv, noise-free, against the creep function of a
Prony relaxation in the instantaneous convention (its unit-stress strain response, exactly as
damage/viscoelastic.h updates a Maxwell branch), convolved with the elastic angle's increments.
Calibrates the total gamma and a characteristic tau (3 starts, least squares) for each shape:
  one            one term
  flatN_R        N terms, tau ratio R between neighbours, equal weights
  powN_R_n       N terms, ratio R, weights ~ tau_i^n
Usage: /usr/bin/python3 bench/notes/2026-11-29-diag3-spectrum.py one pow3_10_0.25 ...  (numpy, scipy)
With --fatigue also fits creep + the generator's log fatigue (a, N0 free) on the recording with and
without its fatigue (does the shape leave room for the fatigue, and does it invent one?).
"""
import math, os, sys
import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "data", "othermeans"))
import make_recordings as M  # noqa: E402

spec = M.RECORDINGS["creep_fatigue_lag"]
th = M.Elastic(*M.load_curve("small_h6"))
t, u, trial = M.commanded(spec["protocol"])
pc = M.first_order(M.second_order(u, spec["rig"]["regulator_hz"], spec["rig"]["regulator_zeta"]), 0.3)
P_REF = 30.0
S = 5  # model step 5 x 2 ms
dtm = M.DT * S
pcs, trs = pc[::S], trial[::S]
Nc = np.cumsum(np.power(np.clip(pcs, 0, None) / P_REF, 2.0) / 8.0) * dtm  # FATIGUE_LOG's cycle count
nfft = 1 << int(math.ceil(math.log2(2 * len(pcs))))


def truth(effects):
    return M.structure(t, pc, th, effects, P_REF)[::S]


def shape(name, gam, tc):
    """Abaqus g_i (fractions of the instantaneous modulus) and tau_i of a shape at total gamma, tau."""
    if name == "one":
        gi, ti = [gam], [tc]
    else:
        kind, rest = name[:4] if name.startswith("flat") else name[:3], name[4:] if name.startswith("flat") else name[3:]
        parts = rest.split("_")
        n_terms, ratio = int(parts[0]), float(parts[1])
        ti = [tc * ratio ** (j - (n_terms - 1) / 2) for j in range(n_terms)]
        w = np.ones(n_terms) if kind == "flat" else np.array([r ** float(parts[2]) for r in ti])
        gi = list(gam * w / w.sum())
    G = sum(gi)
    return [x / (1 + G) for x in gi], ti


def creep_function(g, tau):
    """Strain under a unit stress step, relative to the instantaneous strain, minus 1."""
    g, tau = np.asarray(g, float), np.asarray(tau, float)
    beta = 1 - g.sum()
    x = dtm / tau
    e = np.exp(-x)
    k = (1 - e) / x
    b = beta + (g * k).sum()
    q, eo = np.zeros(len(g)), 0.0
    out = np.empty(len(pcs))
    for n in range(len(pcs)):
        H = (e * q - g * k * eo).sum()
        ep = (1.0 - H) / b
        q = e * q + g * k * (ep - eo)
        eo = ep
        out[n] = ep
    return out / out[0] - 1.0


def predict(par, name, fat):
    g, tau = shape(name, math.exp(par[0]), math.exp(par[1]))
    q = pcs * (1 + par[2] * np.log1p(Nc / math.exp(par[3]))) if fat else pcs
    te = th(q)
    d = np.diff(te, prepend=0.0)
    return te + np.fft.irfft(np.fft.rfft(d, nfft) * np.fft.rfft(creep_function(g, tau), nfft), nfft)[: len(pcs)]


def fit(T, name, fat):
    best = None
    for t0 in (0.5, 3.0, 20.0):
        x0 = [math.log(0.3), math.log(t0)] + ([0.02, math.log(0.5)] if fat else [])
        lo = [math.log(0.005), math.log(0.05)] + ([0.0, math.log(0.01)] if fat else [])
        hi = [math.log(5), math.log(300)] + ([0.3, math.log(100)] if fat else [])
        r = least_squares(lambda p: predict(p, name, fat) - T, x0, bounds=(lo, hi))
        rms = math.sqrt(np.mean(r.fun ** 2))
        if best is None or rms < best[0]:
            best = (rms, r.x, r.fun)
    return best


def main(args):
    fatigue = "--fatigue" in args
    names = [a for a in args if a != "--fatigue"]
    data = {"powerlaw": truth({"creep": M.POWER_CREEP}), "kww": truth({"creep": M.KWW})}
    if fatigue:
        data = {"powerlaw": data["powerlaw"], "powerlaw+fatigue": truth({"creep": M.POWER_CREEP, "fatigue": M.FATIGUE_LOG})}
    for name in names:
        for lab, T in data.items():
            for fat in ((False, True) if fatigue else (False,)):
                rms, x, res = fit(T, name, fat)
                per = " ".join("%.3f" % math.sqrt(np.mean(res[trs == k] ** 2)) for k in range(6))
                extra = (" fatigue a %.3f N0 %.2f" % (x[2], math.exp(x[3]))) if fat else ""
                print("%-14s %-17s %s rms %.4f deg  gamma %.3f tau %.2f s%s | per trial %s" %
                      (name, lab, "+fatigue" if fat else "        ", rms, math.exp(x[0]), math.exp(x[1]), extra, per), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
