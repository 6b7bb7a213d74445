#!/usr/bin/env python3
"""The user guide's commands can be typed as written from a fresh clone (issue 34: "a newcomer can
follow the tutorial from a fresh clone").

Reads the commands of docs/user_guide.md (its indented code lines that start with
`build/app/pneufem`, `cat`, `pvpython` or `./scripts/`) in order and checks, without running them:
  * every file of the repository they name exists (scenes, recordings, scripts; `uniaxial:FILE` too);
  * every file under out/ they read was written by an earlier command (`--out DIR` or `> FILE`),
    so the steps are in an order that works;
  * with the executable given, every option a pneufem command uses is in that command's --help
    (an option renamed in the code and not in the guide fails here).

    /usr/bin/python3 tests/docs/check_tutorial.py REPO [PNEUFEM_EXE]
    /usr/bin/python3 tests/docs/check_tutorial.py --self-test     # the check fails where it must

Prints one line per problem and exits 1, or a summary and exits 0. Standard library only.
"""
import os
import re
import shlex
import subprocess
import sys

STARTS = ("build/app/pneufem ", "cat ", "pvpython ", "./scripts/")


def commands(guide):
    """(line number, command) of the guide's indented command lines, comments stripped."""
    out = []
    with open(guide, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            if not line.startswith("    ") or line.startswith("     "):
                continue
            text = line[4:].rstrip("\n")
            if text.startswith(STARTS):
                out.append((n, re.sub(r"\s+#.*$", "", text)))
    return out


def check(repo, exe=None):
    problems, written, helps = [], [], {}
    cmds = commands(os.path.join(repo, "docs", "user_guide.md"))
    for n, cmd in cmds:
        where = "docs/user_guide.md:%d: %s" % (n, cmd)
        tokens = shlex.split(cmd)
        outputs = []
        for i, tok in enumerate(tokens):
            prev = tokens[i - 1] if i else ""
            if prev in ("--out", ">"):
                outputs.append(tok)
                continue
            path = tok.split(":", 1)[1] if re.match(r"^[a-z]+:", tok) else tok
            if tok.startswith("-") or "/" not in path or path.startswith("build/"):
                continue
            if path.startswith("out/"):
                if not any(path == w or path.startswith(w.rstrip("/") + "/") for w in written):
                    problems.append("%s: reads %s, which no earlier command writes" % (where, path))
            elif not os.path.exists(os.path.join(repo, path)):
                problems.append("%s: %s is not in the repository" % (where, path))
        written += outputs
        if exe and tokens[0] == "build/app/pneufem" and len(tokens) > 1:
            sub = tokens[1]
            if sub not in helps:
                run = subprocess.run([exe, sub, "--help"], capture_output=True, text=True)
                helps[sub] = run.stdout + run.stderr if run.returncode == 0 else None
            if helps[sub] is None:
                problems.append("%s: `pneufem %s --help` fails: no such command?" % (where, sub))
                continue
            for tok in tokens[2:]:
                opt = tok.split("=", 1)[0]
                if opt.startswith("--") and not re.search(re.escape(opt) + r"\b", helps[sub]):
                    problems.append("%s: %s is not an option of `pneufem %s`" % (where, opt, sub))
    return cmds, problems


def self_test():
    """A made-up repository whose guide names a missing file and reads out/ before writing it."""
    import tempfile
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "docs"))
        os.makedirs(os.path.join(root, "scenes"))
        open(os.path.join(root, "scenes", "a.toml"), "w").close()
        guide = ("Text.\n\n"
                 "    build/app/pneufem simulate scenes/a.toml --out out/first   # fine\n"
                 "    build/app/pneufem compare out/first/scene.toml --data tests/missing.csv --out out/study\n"
                 "    build/app/pneufem compare out/fitted.toml --out out/x\n"
                 "    cat out/study/a.toml > out/b.toml\n")
        with open(os.path.join(root, "docs", "user_guide.md"), "w") as f:
            f.write(guide)
        cmds, problems = check(root)
        assert len(cmds) == 4, cmds
        assert len(problems) == 2, problems
        assert "tests/missing.csv is not in the repository" in problems[0], problems
        assert "reads out/fitted.toml, which no earlier command writes" in problems[1], problems
    print("check_tutorial self-test: ok")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    cmds, problems = check(sys.argv[1], sys.argv[2] if len(sys.argv) == 3 else None)
    for p in problems:
        print(p)
    if not cmds:
        print("docs/user_guide.md: no commands found")
        return 1
    if not problems:
        print("%d commands of the user guide: files present, out/ inputs written before they are read%s"
              % (len(cmds), ", options known" if len(sys.argv) == 3 else ""))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
