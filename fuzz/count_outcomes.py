#!/usr/bin/env python3
"""Counts what a fuzz target makes of every input of a corpus (RELIABILITY.md).

    fuzz/count_outcomes.py BUILD_DIR/fuzz/fuzz_inp DIR [DIR...]

Replays the corpus with PNEUFEM_FUZZ_REPORT=1 (fuzz/report.h) and counts the inputs read, the
inputs refused with a clear message (it names where - "<file>:<line>", an element or node, a scene
key or a --set - and says what to do or what is allowed: after "; ", an example ("e.g."), the
values allowed ("must be", "allowed", "expected") or where to find them), and the others, a few of
which are printed. A crash stops the replay
and is reported by libFuzzer as usual."""
import re
import subprocess
import sys
import os

exe, dirs = sys.argv[1], sys.argv[2:]
env = dict(os.environ, PNEUFEM_FUZZ_REPORT="1")
out = subprocess.run([exe, "-runs=0", *dirs], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                     text=True, errors="replace").stdout
where = re.compile(r"^(\S+:\d+|--set |[^:]*: key '|default scene: key ')|\b(element|node) \S*\d")
accepted = clear = unclear = 0
examples = []
for line in out.split("\n"):
    if not line.startswith("pneufem-fuzz: "):
        continue
    rest = line[len("pneufem-fuzz: "):]
    if rest.startswith("accepted"):
        accepted += 1
        continue
    msg = rest[len("error "):]
    if where.search(msg) and re.search(r"; |e\.g\.|lists every key|must be|allowed|expected", msg):
        clear += 1
    else:
        unclear += 1
        if len(examples) < 8:
            examples.append(msg[:200])
total = accepted + clear + unclear
print(f"{os.path.basename(exe)}: {total} inputs: {accepted} read, {clear} refused with a clear message, "
      f"{unclear} refused otherwise")
for e in examples:
    print("  unclear:", e)
if "ERROR: libFuzzer" in out or "runtime error" in out:
    print("  a finding during the replay: run the target on the corpus to see it")
    sys.exit(1)
