#!/usr/bin/env python3
"""Largest |reduced - FEM| per trial of a bench_rom log against the FEM record of
../rom_h6_corrected/fem_and_reduced_three_trials.log (same scene, same constants).
Usage: compare_with_fem.py LOG [v]   (v: every report from 98.5 s on)."""
import collections, os, re, sys

here = os.path.dirname(os.path.abspath(__file__))
fem = {}
for l in open(os.path.join(here, '..', 'rom_h6_corrected', 'fem_and_reduced_three_trials.log')):
    f = l.split()
    if len(f) >= 8 and f[0].isdigit() and re.match(r'^-?\d+\.\d+$', f[1]):
        fem[(int(f[0]), f[1])] = (float(f[3]), float(f[4]))
rom = {}
for l in open(sys.argv[1]):
    m = re.match(r'^\s+(\d+)\s+([\d.]+)\s+([\d.]+)\s+(-?[\d.]+) \(ideal', l)
    if m:
        rom[(int(m.group(1)), m.group(2))] = float(m.group(4))
worst, worst_old = collections.defaultdict(float), collections.defaultdict(float)
for k, v in rom.items():
    if k in fem:
        worst[k[0]] = max(worst[k[0]], abs(v - fem[k][0]))
        worst_old[k[0]] = max(worst_old[k[0]], abs(fem[k][1] - fem[k][0]))
for t in sorted(worst):
    print(t, 'this log %.3f  plain basis, linear load %.3f' % (worst[t], worst_old[t]))
if len(sys.argv) > 2:
    for k in sorted(rom, key=lambda k: (k[0], float(k[1]))):
        if k in fem and float(k[1]) >= 98:
            print(k, 'fem %.3f reduced %.3f diff %+.3f' % (fem[k][0], rom[k], rom[k] - fem[k][0]))
