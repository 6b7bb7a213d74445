#!/usr/bin/env python3
"""Checks the include graph of the C++ sources: the subsystems are folders stacked in layers, and no
file includes a folder above its own, nor a folder beside it on the same layer; and no loop runs
between files.

A unit is a .h/.cpp pair with the same path stem (engine/rom.h + engine/rom.cpp; a lone .h or .cpp is
its own unit). An edge is an #include "..." of a project file, resolved the way the build does: first
beside the including file, then from the repository root (every library's include directory is
${PROJECT_SOURCE_DIR}; the generated headers of the build tree, core/version_info.h and
scenes/default_scene_text.h, are placed by their path). An #include <...> counts only when it names a
project file from the root (<engine/mesh.h>); <vector>, <Eigen/Core> are not the project's.

It fails (exit 1, one line per problem, each with file:line) on
  * a loop between units (a strongly connected component of the unit graph, found by Tarjan's
    algorithm) that is not in ALLOWED_LOOPS, and an entry of ALLOWED_LOOPS that is no longer a loop
    as written (so the list cannot go stale);
  * an include of a folder on a higher layer of LAYERS, or of another folder of the same layer, not in
    ALLOWED_INCLUDES, and an entry of ALLOWED_INCLUDES that no longer occurs;
  * a folder holding sources that LAYERS does not place, and a folder of LAYERS that holds none.

Usage: check_includes.py REPO_ROOT      check the repository
       check_includes.py --self-test    check the checker on a made-up tree with a loop, an upward
                                        and a sideways include (it must report all three)
"""
import os
import re
import sys
import tempfile

# The layers, bottom first. A file may include its own folder and the folders of the layers below its
# own; not a folder above, nor another folder of its own layer. A folder is the longest declared path
# that contains the file: scenes/inp/reader.cpp is in scenes/inp, scenes/scene.cpp in scenes. Every
# folder holding sources must be declared, except below the folders of the top layer, which own their
# sub-folders (tests/engine is tests). The layers follow the libraries' links (the CMakeLists.txt).
LAYERS = [
    ("core",),                     # errors, atomic files, JSON and number text, version: the standard library only
    ("materials", "analysis"),     # constitutive laws | measured data (knows nothing of the FEM)
    ("damage", "engine"),          # effects decorating the laws | the finite elements and solvers
    ("fit", "scenes/inp", "scenes/stl", "viz"),  # fitting laws | decks | CAD surfaces | VTU and plots
    ("scenes",),                   # a scene file to a model
    ("app/simulate", "app/fit_material", "app/sweep"),  # the commands, each in its folder ...
    ("app/compare",),              # ... compare runs simulate
    ("app/diagnose",),             # ... diagnose runs compare and simulate
    ("app/synth",),                # ... synth runs diagnose's evaluator
    ("app",),                      # main.cpp: registers every command
    ("bench", "fuzz", "python", "tests"),  # drivers: may include anything below, nothing includes them
]

# Loops left on purpose: the units of each loop exactly as the check finds them, with the reason.
ALLOWED_LOOPS = []

# Upward or sideways includes left on purpose: ("file", "included file") -> reason. None today.
ALLOWED_INCLUDES = {}

SOURCE_EXT = (".h", ".hh", ".hpp", ".inl", ".ipp", ".c", ".cc", ".cpp", ".cxx")
INCLUDE = re.compile(r'^\s*#\s*include\s*(?:"([^"]+)"|<([^>]+)>)')


def norm(path):
    return os.path.normpath(path).replace(os.sep, "/")


def sources(root):
    """Every source file under root, as a repository path; hidden folders and build trees (a
    CMakeCache.txt, or build*/out* at the top as .gitignore says) are skipped."""
    found = []
    for dirpath, dirs, files in os.walk(root):
        top = os.path.samefile(dirpath, root)
        dirs[:] = sorted(d for d in dirs if not d.startswith(".")
                         and not (top and (d.startswith("build") or d.startswith("out")))
                         and not os.path.exists(os.path.join(dirpath, d, "CMakeCache.txt")))
        for f in sorted(files):
            if f.endswith(SOURCE_EXT):
                found.append(norm(os.path.relpath(os.path.join(dirpath, f), root)))
    return found


def unit(path):
    return os.path.splitext(path)[0]


def includes(root, files):
    """(file, line, written, resolved) for every #include "..."; resolved is a repository path, or
    None when the file is not in the tree (a generated header, or not the project's)."""
    present = set(files)
    out = []
    for f in files:
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as text:
            for n, line in enumerate(text, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                written = m.group(1) or m.group(2)
                beside = norm(os.path.join(os.path.dirname(f), written))
                from_root = norm(written)
                if m.group(1) is None:  # <...>: the project's only when it names a file from the root
                    if from_root in present:
                        out.append((f, n, written, from_root))
                    continue
                resolved = beside if beside in present else from_root if from_root in present else None
                out.append((f, n, written, resolved))
    return out


def strongly_connected(graph):
    """Tarjan's algorithm (iterative): the components of more than one node."""
    index, low, on_stack, stack, comps = {}, {}, set(), [], []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            v, children = work[-1]
            advanced = False
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    advanced = True
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    comps.append(set(comp))
    return comps


def check(root, layers, allowed_loops, allowed_includes):
    """The problems of the tree at root (a list of lines) and a summary line."""
    problems = []
    level, open_folders = {}, set(layers[-1])
    for i, layer in enumerate(layers):
        for folder in layer:
            if folder in level:
                problems.append(f"check_includes.py: LAYERS: {folder} is declared twice")
            level[folder] = i

    def folder_of(path):
        parts = path.split("/")[:-1]
        for k in range(len(parts), 0, -1):
            if "/".join(parts[:k]) in level:
                return "/".join(parts[:k])
        return None

    files = sources(root)
    used_folders = set()
    for d in sorted({os.path.dirname(f) for f in files}):
        owner = folder_of(d + "/x")
        if d in level or (owner in open_folders):
            used_folders.add(owner)
        else:
            problems.append(f"{d}/: a folder of sources that LAYERS does not place: add it to a layer of "
                            f"tests/docs/check_includes.py (which folders may it include, which include it?)")
    for folder in sorted(set(level) - used_folders):
        problems.append(f"check_includes.py: LAYERS: {folder} holds no sources: remove it or correct its path")

    edges = includes(root, files)

    # (b) upward and sideways includes between folders
    seen_allowed = set()
    for f, n, written, resolved in edges:
        target = resolved or norm(written)
        a, b = folder_of(f), folder_of(target)
        if a is None or b is None or a == b:
            continue
        if level[b] < level[a]:
            continue
        if (f, target) in allowed_includes:
            seen_allowed.add((f, target))
            continue
        how = "upward" if level[b] > level[a] else "sideways"
        problems.append(f"{f}:{n}: {how} include of {target}: {a}/ (layer {level[a]}) may not include {b}/ "
                        f"(layer {level[b]}); move what it needs down, or change LAYERS if the layering is wrong")
    for (f, target) in sorted(set(allowed_includes) - seen_allowed):
        problems.append(f"{f}: ALLOWED_INCLUDES lists its include of {target}, which is gone or no longer "
                        f"crosses a layer: remove the entry")

    # (a) loops between units
    graph = {}
    where = {}
    for f, n, written, resolved in edges:
        if resolved is None or unit(f) == unit(resolved):
            continue
        graph.setdefault(unit(f), set()).add(unit(resolved))
        graph.setdefault(unit(resolved), set())
        where.setdefault((unit(f), unit(resolved)), []).append((f, n, f"{f}:{n} includes {written}"))
    loops = strongly_connected(graph)
    allowed = [(set(units), reason) for units, reason in allowed_loops]
    matched = set()
    for comp in sorted(loops, key=sorted):
        hit = [i for i, (units, _) in enumerate(allowed) if units == comp]
        if hit:
            matched.add(hit[0])
            continue
        names = sorted(u for u in {x for x in files if unit(x) in comp})
        lines = [w for _, _, w in sorted(w for (a, b), ws in where.items() if a in comp and b in comp for w in ws)]
        problems.append(f"loop between {len(comp)} units ({', '.join(names)}):\n    " + "\n    ".join(lines)
                        + "\n    break it: move what both need into a unit of its own, or pass only the values needed")
    for i, (units, reason) in enumerate(allowed):
        if i in matched:
            continue
        now = [c for c in loops if c & units]
        what = (f"the loop is now {{{', '.join(sorted(now[0]))}}}: update the entry" if now
                else "it is broken: remove the entry")
        problems.append(f"ALLOWED_LOOPS lists {{{', '.join(sorted(units))}}} ({reason}), which is no longer a loop as "
                        f"written; {what}")

    summary = (f"{len(files)} files, {len(graph)} units with includes, {len(edges)} project includes; "
               f"{len(loops)} loop(s), {len(matched)} of them allowed on purpose")
    return problems, summary


def self_test():
    """The checker must be able to fail: a made-up tree with a loop (a.h -> b.h, b.cpp -> "a.h" beside
    it), an upward include (core -> engine), a sideways one (materials -> analysis) and an undeclared
    folder must give each problem, and the same tree without them none."""
    layers = [("core",), ("materials", "analysis"), ("engine",), ("tests",)]
    clean = {
        "core/base.h": "#pragma once\n",
        "core/base.cpp": '#include "core/base.h"\n#include <vector>\n',
        "materials/law.h": '#pragma once\n#include "core/base.h"\n',
        "analysis/csv.h": '#pragma once\n#include "core/base.h"\n',
        "engine/a.h": '#pragma once\n#include "materials/law.h"\n',
        "engine/b.h": "#pragma once\n",
        "engine/b.cpp": '#include "engine/b.h"\n',
        "tests/engine/test_a.cpp": '#include "engine/a.h"\n#include "helper.h"\n',
        "tests/engine/helper.h": '#pragma once\n#include "analysis/csv.h"\n',
        "build/CMakeCache.txt": "",
        "build/core/generated.h": '#include "engine/a.h"\n',  # a build tree is not the project's
    }
    broken = dict(clean)
    broken["engine/a.h"] = '#pragma once\n#include "materials/law.h"\n#include "engine/b.h"\n'
    broken["engine/b.cpp"] = '#include "engine/b.h"\n\n#include "a.h"\n'  # beside it: engine/a.h
    broken["core/clock.cpp"] = '#include "core/base.h"\n#include "engine/b.h"\n'
    broken["materials/law.h"] = '#pragma once\n#include "core/base.h"\n#include "analysis/csv.h"\n'
    broken["extra/tool.cpp"] = '#include "core/base.h"\n'
    broken["analysis/reader.cpp"] = '#include <vector>\n#include <engine/b.h>\n'  # the project's, in brackets
    failures = []

    def run(tree, loops=(), allowed_includes=None, label=""):
        with tempfile.TemporaryDirectory(prefix="check_includes_") as root:
            for path, text in tree.items():
                os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
                with open(os.path.join(root, path), "w", encoding="utf-8") as out:
                    out.write(text)
            problems, _ = check(root, layers, list(loops), allowed_includes or {})
        return "\n".join(problems), len(problems)

    def expect(condition, what, text):
        if not condition:
            failures.append(f"{what}; the check printed:\n{text or '(nothing)'}")

    text, count = run(clean)
    expect(count == 0, "the clean tree gives problems", text)

    text, count = run(broken)
    expect("loop between 2 units (engine/a.h, engine/b.cpp, engine/b.h)" in text, "the loop is not reported", text)
    expect("engine/a.h:3 includes engine/b.h" in text and "engine/b.cpp:3 includes a.h" in text,
           "the loop's includes are not named with file:line", text)
    expect("core/clock.cpp:2: upward include of engine/b.h" in text, "the upward include is not reported", text)
    expect("materials/law.h:3: sideways include of analysis/csv.h" in text, "the sideways include is not reported", text)
    expect("extra/: a folder of sources that LAYERS does not place" in text, "the undeclared folder is not reported", text)
    expect("analysis/reader.cpp:2: upward include of engine/b.h" in text, "the upward #include <...> is not reported", text)
    expect(count == 5, f"{count} problems instead of 5", text)

    text, count = run(broken, loops=[({"engine/a", "engine/b"}, "on purpose")],
                      allowed_includes={("core/clock.cpp", "engine/b.h"): "on purpose"})
    expect("loop between" not in text and "core/clock.cpp" not in text and count == 3,
           "an allowed loop or include is reported", text)

    text, count = run(clean, loops=[({"engine/a", "engine/b"}, "on purpose")],
                      allowed_includes={("core/clock.cpp", "engine/b.h"): "on purpose"})
    expect("ALLOWED_LOOPS lists {engine/a, engine/b} (on purpose), which is no longer a loop" in text,
           "a stale allowed loop is not reported", text)
    expect("ALLOWED_INCLUDES lists its include of engine/b.h, which is gone" in text,
           "a stale allowed include is not reported", text)

    text, count = run(broken, loops=[({"engine/a", "engine/c"}, "on purpose")])
    expect("the loop is now {engine/a, engine/b}: update the entry" in text,
           "an allowed loop that changed is not reported as such", text)

    for f in failures:
        print("self-test: " + f)
    print("self-test: " + ("FAILED" if failures else "the checker reports loops, upward and sideways includes, "
                           "undeclared folders and stale allowances"))
    return 1 if failures else 0


def main():
    if len(sys.argv) == 2 and sys.argv[1] == "--self-test":
        return self_test()
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        print(__doc__.strip().split("\n\n")[-1], file=sys.stderr)
        return 2
    root = os.path.realpath(sys.argv[1])
    problems, summary = check(root, LAYERS, ALLOWED_LOOPS, ALLOWED_INCLUDES)
    for p in problems:
        print(p)
    print(summary)
    for units, reason in ALLOWED_LOOPS:
        print(f"  allowed loop {{{', '.join(sorted(units))}}}: {reason}")
    if problems:
        print(f"{len(problems)} problem(s): the layers and the allowances are declared at the top of "
              f"tests/docs/check_includes.py")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
