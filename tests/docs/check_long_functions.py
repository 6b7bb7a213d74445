"""Functions a person can hold (issue 34, item 4): no function of the sources over LIMIT lines
(100) without a reason written beside it, in the comment directly above it, that says it is so
"on purpose" (e.g. "One function (~120 lines) on purpose: the iteration, its line search and ...").

The functions and their lengths are Universal Ctags' (scripts/long_functions.sh lists them); without
ctags (Debian's universal-ctags) the check is skipped, exit 77. The folders are the product's:
tests, benchmarks, fuzzers and python/ are left out, as in scripts/long_functions.sh.

    /usr/bin/python3 tests/docs/check_long_functions.py REPO [LIMIT]
    /usr/bin/python3 tests/docs/check_long_functions.py --self-test
"""
import os
import shutil
import subprocess
import sys
import tempfile

FOLDERS = ["core", "materials", "damage", "engine", "fit", "scenes", "analysis", "viz", "app"]
REASON = "on purpose"
SKIP = 77


def functions(repo, folders):
    """(file, first line, last line, name) of every function definition ctags finds."""
    present = [f for f in folders if os.path.isdir(os.path.join(repo, f))]
    out = subprocess.run(["ctags", "-x", "--_xformat=%N\t%F\t%n\t%{end}", "--c++-kinds=f", "--fields=+ne", "-R",
                          "--languages=C++"] + present, cwd=repo, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                         text=True, check=True).stdout
    for line in out.splitlines():
        name, path, first, last = line.split("\t")
        if last:
            yield path, int(first), int(last), name


def comment_above(lines, first):
    """The comment lines directly above line `first` (1-based), down to the first line that is not one."""
    block, i = [], first - 2
    while i >= 0 and lines[i].lstrip().startswith(("//", "/*", "*")):
        block.append(lines[i])
        i -= 1
    return "\n".join(reversed(block))


def problems(repo, limit, folders=FOLDERS):
    found, count = [], 0
    for path, first, last, name in functions(repo, folders):
        n = last - first + 1
        if n <= limit:
            continue
        count += 1
        with open(os.path.join(repo, path), encoding="utf-8", errors="replace") as f:
            lines = f.read().split("\n")
        if REASON not in comment_above(lines, first):
            found.append("%s:%d: %s is %d lines, over %d, with no reason beside it: split it, or say in the comment "
                         "directly above it why it is one function (\"... on purpose: ...\")" % (path, first, name, n, limit))
    return found, count


def self_test():
    body = "\n".join("  x += %d;" % i for i in range(120))
    with tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(d, "core"))
        with open(os.path.join(d, "core", "a.cpp"), "w") as f:
            f.write("int short_one() { return 1; }\n\n"
                    "// One function (~120 lines) on purpose: a table.\nint with_reason() {\n  int x = 0;\n%s\n  return x;\n}\n\n"
                    "// A long function.\nint without_reason() {\n  int x = 0;\n%s\n  return x;\n}\n" % (body, body))
        found, count = problems(d, 100, ["core"])
    assert count == 2, count
    assert len(found) == 1 and "without_reason" in found[0] and "core/a.cpp:" in found[0], found
    print("self-test: a long function without a reason is reported, one with a reason and a short one are not")


def main():
    if not shutil.which("ctags"):
        print("SKIPPED: ctags (Universal Ctags, Debian's universal-ctags) not found")
        sys.exit(SKIP)
    if sys.argv[1:] == ["--self-test"]:
        self_test()
        return
    repo = sys.argv[1]
    limit = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    found, count = problems(repo, limit)
    for p in found:
        print(p)
    print("%d function(s) over %d lines, %d without a reason beside them" % (count, limit, len(found)))
    sys.exit(1 if found else 0)


main()
