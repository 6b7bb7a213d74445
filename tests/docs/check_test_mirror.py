#!/usr/bin/env python3
"""Checks that tests/ mirrors the sources: every source unit with logic of its own has a test file of
the mirrored name, or an entry in MAPPED below that names the test files that test it and says why it
is not mirrored.

A source unit with logic of its own is every .cpp (.cc, .cxx) of the product folders (PRODUCT: core,
materials, damage, analysis, engine, fit, scenes, viz, app, with their sub-folders), and every lone
header there (no .cpp of the same stem) that holds a function body: an inline function, a
constructor, a lambda. Headers of declarations and structs only are not units. Its mirrored test file
is tests/<folder>/test_<stem>.cpp: engine/angle.cpp -> tests/engine/test_angle.cpp,
scenes/inp/reader.cpp -> tests/scenes/inp/test_reader.cpp, analysis/robust.h ->
tests/analysis/test_robust.cpp. A test file is only a test when the CMakeLists.txt of its folder
builds it, so the mirrored and the mapped test files must be named there.

An entry of MAPPED names the unit, the test files, and the reason; the check makes the link real:
  * by(tests, why): each test file includes the unit's header (the .h of the same stem, or the lone
    header itself), directly or through a helper header of tests/;
  * by(tests, why, through=H): each test file includes the unit's header or H, a project header that
    the unit includes, directly or through headers of its folder (the unit implements H: a lone .cpp
    such as app/diagnose/fem.cpp implements evaluator.h; scenes/inp/read_parts.cpp implements
    reader.h, the reader behind deck.h), or whose own files include the unit's header (H's code calls
    the unit: scene.cpp includes deck_materials.h);
  * runs(tests, why): the unit is a command's registration or main(): each test file runs the pneufem
    executable (PNEUFEM_EXE, tests/app/cli_helpers.h) with one of the subcommands the unit registers
    (add_subcommand("name", ...)), e.g. run("compare ..."); for a unit that registers none, any run.

It fails (exit 1, one line per problem: the file and what to do) on
  * a unit with neither a mirrored test file nor an entry;
  * an entry whose test file does not exist, is not built by its folder's CMakeLists.txt, or does
    not include (or run) the unit as above, or whose `through` header is not linked to the unit;
  * a stale entry: its unit no longer exists, no longer has logic of its own, or now has a mirrored
    test file (then the entry is to be removed);
  * a mirrored test file not built by its folder's CMakeLists.txt;
  * a top-level folder holding C++ sources that is neither in PRODUCT nor in NOT_MIRRORED, and a
    folder of NOT_MIRRORED that holds none.

Usage: check_test_mirror.py REPO_ROOT      check the repository
       check_test_mirror.py --self-test    check the checker on a made-up tree (it must report an
                                           unmapped unit, each kind of bad and stale entry)
"""
import os
import re
import sys
import tempfile

# The folders whose units must be mirrored in tests/ (with their sub-folders: scenes/inp, app/diagnose).
PRODUCT = ("core", "materials", "damage", "analysis", "engine", "fit", "scenes", "viz", "app")

# Top-level folders with C++ sources that are not mirrored, and why.
NOT_MIRRORED = {
    "tests": "the tests themselves",
    "bench": "benchmark drivers: they measure, they do not assert",
    "fuzz": "fuzz targets: each is a test of the reader it feeds (scripts/fuzz.sh)",
    "python": "the Python bindings: python/tests tests them through pytest",
}


def by(tests, why, through=None):
    return {"tests": tuple(tests), "why": why, "through": through, "runs": False}


def runs(tests, why):
    return {"tests": tuple(tests), "why": why, "through": None, "runs": True}


_CLI = "registration only (the command's options to its Options struct); run through the executable by "
# Units tested under another name, with the test files that test them and why they are not mirrored.
# Keep it short: where a test file tests exactly one unit, rename it to the mirrored name instead; a
# new unit gets its mirrored test file, not an entry here.
MAPPED = {
    "damage/fatigue_uniform.cpp": by(["tests/app/diagnose/test_fatigue_uniform.cpp"], "the law and its diagnose catalog "
                                     "form are tested in one file (the catalog's candidate builds the law)"),
    # app/: the commands' registrations and main() are run through the executable
    "app/main.cpp": runs(["tests/app/test_cli.cpp"], "main(): registers every command; --help, exit codes and "
                         "each command's dispatch are tested through the executable"),
    "app/compare/cli.cpp": runs(["tests/app/compare/test_command.cpp"], _CLI + "tests/app/compare/test_command.cpp"),
    "app/diagnose/cli.cpp": runs(["tests/app/test_cli.cpp"], _CLI + "tests/app/test_cli.cpp"),
    "app/fit_material/cli.cpp": runs(["tests/app/fit_material/test_command.cpp"],
                                     _CLI + "tests/app/fit_material/test_command.cpp"),
    "app/simulate/cli.cpp": runs(["tests/app/test_cli.cpp"], _CLI + "tests/app/test_cli.cpp"),
    "app/sweep/cli.cpp": runs(["tests/app/sweep/test_command.cpp"], _CLI + "tests/app/sweep/test_command.cpp"),
    "app/synth/cli.cpp": runs(["tests/app/synth/test_command.cpp"], _CLI + "tests/app/synth/test_command.cpp"),
    # app/simulate
    "app/simulate/command.cpp": by(["tests/app/simulate/test_console.cpp", "tests/app/simulate/test_reduced.cpp"],
                                   "run_simulation is tested by what it prints (test_console.cpp), by its "
                                   "reduced-model path (test_reduced.cpp) and through the executable (test_cli.cpp)"),
    # app/diagnose: these need a whole diagnosis (minutes of FEM for the elastic path), which
    # test_output.cpp runs once for the files written and the report (a suite fixture: two recordings)
    "app/diagnose/evaluator.cpp": by(["tests/app/diagnose/test_output.cpp"],
                                     "the reduced-model replay and its cache are tested through diagnoses: its "
                                     "cache through test_output.cpp's second recording, its replays by every "
                                     "diagnosis test (test_command.cpp); a test of its own would trace an elastic path"),
    "app/diagnose/fem.cpp": by(["tests/app/diagnose/test_output.cpp"],
                               "refine_with_fem and verify_with_fem run inside run_diagnosis; --fem-calibrate and "
                               "--refine are tested by DiagnoseFem.* and DiagnoseRefinement.* of test_command.cpp "
                               "(they share its hidden-dataset helpers and FEM cache), their absence here",
                               through="app/diagnose/evaluator.h"),
    "app/diagnose/report.cpp": by(["tests/app/diagnose/test_output.cpp"],
                                  "report.md is one of the files written: its test shares test_output.cpp's "
                                  "diagnoses (ReportHoldsThePerTrialTableOfDiagnosisJson)",
                                  through="app/diagnose/evaluator.h"),
    # engine/
    "engine/quasi_static.cpp": by(["tests/engine/test_pneunet_solvers.cpp", "tests/engine/test_creep.cpp",
                                   "tests/engine/test_cycle_jump.cpp"],
                                  "the quasi-static driver: each solver and its globalisation on a pneu-net, creep "
                                  "and the cycle jump are the driver's tests under the names of what they drive"),
    "engine/reduced_basis.cpp": by(["tests/engine/test_rom.cpp"], "the reduced model's files are being edited in "
                                   "parallel (issue 28); test_rom.cpp tests them through rom.h",
                                   through="engine/rom.h"),
    "engine/rom_basis.cpp": by(["tests/engine/test_rom.cpp"], "implements rom.h (see reduced_basis.cpp)",
                               through="engine/rom.h"),
    "engine/rom_points.cpp": by(["tests/engine/test_rom.cpp"], "the hyper-reduction points, through rom.h (see "
                                "reduced_basis.cpp)", through="engine/rom.h"),
    "engine/rom_replay.cpp": by(["tests/engine/test_rom.cpp"], "implements rom.h (see reduced_basis.cpp)",
                                through="engine/rom.h"),
    # scenes/
    "scenes/calculix_deck.cpp": by(["tests/app/simulate/test_deck_round_trip.cpp",
                                    "tests/scenes/test_fabric_membrane.cpp"],
                                   "the CalculiX deck a scene writes is tested by reading it back (deck round trip) "
                                   "and with the fabric membrane it writes"),
    "scenes/inp/read_parts.cpp": by(["tests/scenes/inp/test_assembly.cpp"],
                                    "the Abaqus/CAE parts and instances of a deck: DeckReader's methods (reader.h), "
                                    "run by read_inp (deck.h), tested with the assembly they make",
                                    through="scenes/inp/deck.h"),
    "scenes/scene_materials.cpp": by(["tests/scenes/test_build_model.cpp"], "the [materials] tables of a scene to "
                                     "laws: part of build_model, tested through it", through="scenes/build_model.h"),
    "scenes/stl/stuffing.cpp": by(["tests/scenes/stl/test_smoothing.cpp"], "isosurface stuffing is tested with the "
                                  "smoothing of the tetrahedra it makes"),
}

IMPL_EXT = (".cpp", ".cc", ".cxx", ".c")
HEADER_EXT = (".h", ".hh", ".hpp", ".inl", ".ipp")
INCLUDE = re.compile(r'^\s*#\s*include\s*(?:"([^"]+)"|<([^>]+)>)', re.M)
COMMENT_OR_STRING = re.compile(r'//[^\n]*|/\*.*?\*/|R"(\w*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)
# A function body: ") {" with qualifiers or a trailing return type between (the ")" of a parameter
# list, of a constructor's last initialiser, or of a lambda's parameters).
BODY = re.compile(r'\)\s*(?:(?:const|noexcept|override|final|mutable)\b\s*|->\s*[\w:<>,&*\s]+?)*\{')
SUBCOMMAND = re.compile(r'add_subcommand\(\s*"([\w-]+)"')


def norm(path):
    return os.path.normpath(path).replace(os.sep, "/")


def read(root, path):
    with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
        return f.read()


def sources(root, folder):
    """Every C++ file under root/folder as a repository path; hidden folders and build trees skipped."""
    found = []
    for dirpath, dirs, files in os.walk(os.path.join(root, folder)):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".")
                         and not os.path.exists(os.path.join(dirpath, d, "CMakeCache.txt")))
        for f in sorted(files):
            if f.endswith(IMPL_EXT + HEADER_EXT):
                found.append(norm(os.path.relpath(os.path.join(dirpath, f), root)))
    return found


def has_body(text):
    return BODY.search(COMMENT_OR_STRING.sub(" ", text)) is not None


def units(root, product):
    """{unit path: its header or None} for the units with logic of their own, and the set of all files."""
    files = [f for folder in product for f in sources(root, folder)]
    present = set(files)
    found = {}
    for f in files:
        stem, ext = os.path.splitext(f)
        headers = [stem + e for e in HEADER_EXT if stem + e in present]
        if ext in IMPL_EXT:
            found[f] = headers[0] if headers else None
        elif not any(stem + e in present for e in IMPL_EXT) and has_body(read(root, f)):
            found[f] = f
    return found, present


def mirror_of(unit):
    folder, name = os.path.split(unit)
    return f"tests/{folder}/test_{os.path.splitext(name)[0]}.cpp"


def project_includes(root, path, text=None):
    """The project files path includes, resolved as the build does (beside it, then from the root)."""
    out = []
    for m in INCLUDE.finditer(read(root, path) if text is None else text):
        written = m.group(1) or m.group(2)
        for cand in ([norm(os.path.join(os.path.dirname(path), written))] if m.group(1) else []) + [norm(written)]:
            if os.path.isfile(os.path.join(root, cand)):
                out.append(cand)
                break
    return out


def reaches(root, unit):
    """The project headers the unit includes, directly or through headers of its own folder."""
    folder = os.path.dirname(unit)
    seen, todo = set(), [unit]
    while todo:
        for inc in project_includes(root, todo.pop()):
            if inc not in seen:
                seen.add(inc)
                if os.path.dirname(inc) == folder:
                    todo.append(inc)
    return seen


def with_helpers(root, test):
    """The test file's text and the project headers it includes, following its helper headers of tests/."""
    seen, todo, texts, included = {test}, [test], [], set()
    while todo:
        f = todo.pop()
        texts.append(read(root, f))
        for inc in project_includes(root, f, texts[-1]):
            included.add(inc)
            if inc.startswith("tests/") and inc not in seen:
                seen.add(inc)
                todo.append(inc)
    return "\n".join(texts), included


def built(root, test):
    """Whether the CMakeLists.txt of the test file's folder names it."""
    cmake = os.path.join(root, os.path.dirname(test), "CMakeLists.txt")
    if not os.path.isfile(cmake):
        return False
    with open(cmake, encoding="utf-8", errors="replace") as f:
        return re.search(r'(?<![\w./-])' + re.escape(os.path.basename(test)) + r'(?![\w.-])', f.read()) is not None


def check(root, product, not_mirrored, mapped):
    """The problems of the tree at root (a list of lines) and a summary line."""
    problems = []
    for top in sorted(os.listdir(root)):
        if (os.path.isdir(os.path.join(root, top)) and not top.startswith(".") and top not in product
                and top not in not_mirrored and not os.path.exists(os.path.join(root, top, "CMakeCache.txt"))
                and not top.startswith("build") and sources(root, top)):
            problems.append(f"{top}/: a folder of C++ sources that is neither mirrored (PRODUCT) nor exempt "
                            f"(NOT_MIRRORED) in tests/docs/check_test_mirror.py: add it to one, with the reason")
    for top in sorted(not_mirrored):
        if not sources(root, top):
            problems.append(f"check_test_mirror.py: NOT_MIRRORED: {top}/ holds no C++ sources: remove it")
    found, present = units(root, product)
    mirrored = [u for u in found if os.path.isfile(os.path.join(root, mirror_of(u)))]
    for u in sorted(mirrored):
        if not built(root, mirror_of(u)):
            problems.append(f"{mirror_of(u)}: the test file of {u} is not built: name it in "
                            f"{os.path.dirname(mirror_of(u))}/CMakeLists.txt")
    for u in sorted(set(found) - set(mirrored) - set(mapped)):
        problems.append(f"{u}: no test file {mirror_of(u)}: write it (and name it in "
                        f"{os.path.dirname(mirror_of(u))}/CMakeLists.txt), or, if another test file tests "
                        f"this unit, add an entry to MAPPED in tests/docs/check_test_mirror.py naming that "
                        f"file and why the test is not mirrored")
    for u, e in sorted(mapped.items()):
        where = f"MAPPED[{u}]"
        if not os.path.isfile(os.path.join(root, u)):
            problems.append(f"{where}: {u} no longer exists: remove the entry")
            continue
        if u not in found:
            problems.append(f"{where}: {u} no longer has logic of its own (a header of declarations only): "
                            f"remove the entry")
            continue
        if u in mirrored:
            problems.append(f"{where}: {u} now has its mirrored test file {mirror_of(u)}: remove the entry "
                            f"(and move the tests the entry names into {mirror_of(u)} if they test it)")
            continue
        if not e["why"].strip() or not e["tests"]:
            problems.append(f"{where}: the entry must name at least one test file and the reason")
        targets = set()
        if e["through"]:
            h = e["through"]
            h_files = [h] + [os.path.splitext(h)[0] + x for x in IMPL_EXT if os.path.splitext(h)[0] + x in present]
            if h not in present:
                problems.append(f"{where}: through={h}, which is not a project header: correct or remove it")
            elif not (h in reaches(root, u) or
                      (found[u] and any(found[u] in project_includes(root, f) for f in h_files))):
                problems.append(f"{where}: through={h}, but {u} does not include {h} (nor do the headers of its "
                                f"folder it includes) nor does "
                                f"{' or '.join(h_files)} include {found[u] or u}'s header: name the header the "
                                f"unit implements or that calls it")
            targets.add(h)
        if found[u]:
            targets.add(found[u])
        elif not e["through"] and not e["runs"]:
            problems.append(f"{where}: {u} has no header of its own: name the header it implements (through=...)")
        names = SUBCOMMAND.findall(read(root, u)) if e["runs"] else []
        for t in e["tests"]:
            if not os.path.isfile(os.path.join(root, t)):
                problems.append(f"{where}: its test file {t} does not exist: correct the entry")
                continue
            if not built(root, t):
                problems.append(f"{where}: its test file {t} is not built by {os.path.dirname(t)}/CMakeLists.txt")
            text, included = with_helpers(root, t)
            if e["runs"]:
                ran = "PNEUFEM_EXE" in text and (not names or any(
                    re.search(r'"' + re.escape(n) + r'[ "]', text) for n in names))
                if not ran:
                    what = (" with " + " or ".join(f'"{n} ..."' for n in names)) if names else ""
                    problems.append(f"{where}: {t} does not run the pneufem executable (PNEUFEM_EXE){what}: "
                                    f"name the test that runs it")
            elif targets and not targets & included:
                problems.append(f"{where}: {t} does not include {' or '.join(sorted(targets))} (nor does a "
                                f"helper of tests/ it includes): name a test file that tests {u}")
    summary = (f"{len(found)} source units with logic of their own: {len(mirrored)} with a mirrored test "
               f"file, {len(set(found) & set(mapped))} mapped to test files of other names "
               f"({sum(1 for u in found if u in mapped and mapped[u]['runs'])} of them through the executable)")
    return problems, summary


def self_test():
    """The checker must be able to fail: a made-up tree with an unmapped unit, a mirrored test that is
    not built, and entries that are bad (missing test file, test that does not include the unit, a
    `through` not linked, a cli entry whose test does not run the command) or stale (unit gone, now
    mirrored, no longer has logic) must give each problem, and the clean tree none."""
    product = ("core", "engine", "app")
    clean = {
        "core/errors.h": "#pragma once\nstruct E { int e() const { return 1; } };\n",  # lone, with a body
        "core/types.h": "#pragma once\nstruct T { int a = 0; void f(int x); };\n",   # lone, declarations
        "core/text.h": "#pragma once\n// a comment with f() { }\nconst char* s = \") {\";\n",  # not a body
        "engine/solve.h": "#pragma once\nint solve();\n",
        "engine/solve.cpp": '#include "engine/solve.h"\nint solve() { return 0; }\n',
        "engine/step.h": "#pragma once\nint step();\n",
        "engine/step.cpp": '#include "engine/step.h"\n#include "engine/solve.h"\nint step() { return solve(); }\n',
        "engine/parts.cpp": '#include "engine/solve.h"\n',  # a lone .cpp implementing solve.h
        "engine/impl.h": '#pragma once\n#include "engine/solve.h"\n',
        "engine/more.cpp": '#include "engine/impl.h"\n',  # implements impl.h, the implementation of solve.h
        "app/run/cli.cpp": 'void reg(App& a) { a.add_subcommand(\n  "run", "Runs"); }\n',
        "app/main.cpp": "int main() { return 0; }\n",
        "tests/CMakeLists.txt": "",
        "tests/core/CMakeLists.txt": "pneufem_test(test_core SOURCES test_errors.cpp)\n",
        "tests/core/test_errors.cpp": '#include "core/errors.h"\n',
        "tests/engine/CMakeLists.txt": "pneufem_test(test_engine SOURCES test_step.cpp test_all.cpp)\n",
        "tests/engine/test_step.cpp": '#include "engine/step.h"\n',
        "tests/engine/test_all.cpp": '#include "tests/engine/helper.h"\n',
        "tests/engine/helper.h": '#pragma once\n#include "engine/solve.h"\n',
        "tests/app/CMakeLists.txt": "pneufem_test(test_cli SOURCES test_cli.cpp)\n",
        "tests/app/test_cli.cpp": '#include "tests/app/h.h"\nTEST(A, B) { run("run --x"); }\n',
        "tests/app/h.h": "std::string e = PNEUFEM_EXE;\n",
        "bench/b.cpp": "int main() { return 0; }\n",
        "build/CMakeCache.txt": "",
        "build/engine/gen.cpp": "int g() { return 0; }\n",
    }
    mapped = {
        "engine/solve.cpp": by(["tests/engine/test_all.cpp"], "with the others, through helper.h"),
        "engine/parts.cpp": by(["tests/engine/test_all.cpp"], "implements solve.h", through="engine/solve.h"),
        "engine/more.cpp": by(["tests/engine/test_all.cpp"], "through impl.h", through="engine/solve.h"),
        "app/run/cli.cpp": runs(["tests/app/test_cli.cpp"], "registration only"),
        "app/main.cpp": runs(["tests/app/test_cli.cpp"], "main()"),
    }
    failures = []

    def run(tree, entries, nm=None):
        with tempfile.TemporaryDirectory(prefix="check_test_mirror_") as root:
            for path, text in tree.items():
                os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
                with open(os.path.join(root, path), "w", encoding="utf-8") as out:
                    out.write(text)
            problems, summary = check(root, product, {"bench": "", "tests": ""} if nm is None else nm, entries)
        return "\n".join(problems), len(problems), summary

    def expect(condition, what, text):
        if not condition:
            failures.append(f"{what}; the check printed:\n{text or '(nothing)'}")

    text, count, summary = run(clean, mapped)
    expect(count == 0, "the clean tree gives problems", text)
    expect(summary.startswith("7 source units with logic of their own: 2 with a mirrored test file, 5 mapped"),
           "the units are not counted as they should be (7: 2 mirrored, 5 mapped)", summary)

    broken = dict(clean)
    broken["engine/new.cpp"] = "int n() { return 1; }\n"                       # unmapped
    broken["tests/core/CMakeLists.txt"] = "pneufem_test(test_core SOURCES test_other_errors.cpp)\n"  # not built
    broken["tests/engine/test_all.cpp"] = '#include "engine/step.h"\n'         # no longer reaches solve.h
    broken["tests/app/test_cli.cpp"] = 'TEST(A, B) { run("walk --x"); }\n'   # runs nothing of cli.cpp
    text, count, _ = run(broken, mapped, nm={"tests": "", "tools": ""})
    expect("engine/new.cpp: no test file tests/engine/test_new.cpp" in text, "the unmapped unit is not reported", text)
    expect("tests/core/test_errors.cpp: the test file of core/errors.h is not built" in text,
           "the mirrored test file that is not built is not reported", text)
    expect("MAPPED[engine/solve.cpp]: tests/engine/test_all.cpp does not include engine/solve.h" in text,
           "a test file that does not include the unit is not reported", text)
    expect("MAPPED[engine/parts.cpp]: tests/engine/test_all.cpp does not include engine/solve.h" in text,
           "a test file that does not include the `through` header is not reported", text)
    expect("MAPPED[app/run/cli.cpp]: tests/app/test_cli.cpp does not run the pneufem executable (PNEUFEM_EXE) "
           'with "run ..."' in text, "a cli entry whose test does not run the command is not reported", text)
    expect("MAPPED[app/main.cpp]: tests/app/test_cli.cpp does not run the pneufem executable" in text,
           "a main() entry whose test does not run the executable is not reported", text)
    expect("bench/: a folder of C++ sources that is neither mirrored" in text,
           "an undeclared top-level folder is not reported", text)
    expect("MAPPED[engine/more.cpp]: tests/engine/test_all.cpp does not include engine/solve.h" in text,
           "a test file that does not include the `through` header (reached through the folder) is not reported", text)
    expect("check_test_mirror.py: NOT_MIRRORED: tools/ holds no C++ sources" in text,
           "an exemption of a folder without sources is not reported", text)
    expect(count == 9, f"{count} problems instead of 9", text)

    stale = dict(mapped)
    stale["engine/gone.cpp"] = by(["tests/engine/test_all.cpp"], "gone")
    stale["engine/step.cpp"] = by(["tests/engine/test_all.cpp"], "now mirrored")
    stale["core/types.h"] = by(["tests/core/test_errors.cpp"], "declarations only")
    stale["core/errors.h"] = by(["tests/core/test_missing.cpp"], "")
    stale["engine/parts.cpp"] = by(["tests/engine/test_all.cpp"], "not linked", through="engine/step.h")
    stale["app/main.cpp"] = by(["tests/app/test_cli.cpp"], "no header")
    text, count, _ = run(clean, stale)
    expect("MAPPED[engine/gone.cpp]: engine/gone.cpp no longer exists: remove the entry" in text,
           "an entry of a unit that is gone is not reported", text)
    expect("MAPPED[engine/step.cpp]: engine/step.cpp now has its mirrored test file tests/engine/test_step.cpp" in text,
           "an entry of a unit that is now mirrored is not reported", text)
    expect("MAPPED[core/types.h]: core/types.h no longer has logic of its own" in text,
           "an entry of a header without a body is not reported", text)
    expect("MAPPED[core/errors.h]: core/errors.h now has its mirrored test file" in text,
           "an entry beside a mirrored test file is not reported", text)
    expect("MAPPED[engine/parts.cpp]: through=engine/step.h, but engine/parts.cpp does not include "
           "engine/step.h" in text,
           "a `through` header that is not linked to the unit is not reported", text)
    expect("MAPPED[app/main.cpp]: app/main.cpp has no header of its own: name the header it implements" in text,
           "a lone .cpp entry without `through` is not reported", text)

    del broken["tests/core/test_errors.cpp"]
    missing = dict(mapped)
    missing["core/errors.h"] = by(["tests/core/test_missing.cpp"], "")
    text, count, _ = run(broken, missing, nm={"tests": "", "bench": ""})
    expect("MAPPED[core/errors.h]: the entry must name at least one test file and the reason" in text,
           "an entry without a reason is not reported", text)
    expect("MAPPED[core/errors.h]: its test file tests/core/test_missing.cpp does not exist" in text,
           "an entry whose test file does not exist is not reported", text)

    for f in failures:
        print("self-test: " + f)
    print("self-test: " + ("FAILED" if failures else "the checker reports unmapped units, unbuilt test files, "
                           "entries whose tests do not reach their unit, and stale entries"))
    return 1 if failures else 0


def main():
    if len(sys.argv) == 2 and sys.argv[1] == "--self-test":
        return self_test()
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        print(__doc__.strip().split("\n\n")[-1], file=sys.stderr)
        return 2
    root = os.path.realpath(sys.argv[1])
    problems, summary = check(root, PRODUCT, NOT_MIRRORED, MAPPED)
    for p in problems:
        print(p)
    print(summary)
    if problems:
        print(f"{len(problems)} problem(s): the rule and the table of units tested under other names are at "
              f"the top of tests/docs/check_test_mirror.py")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
