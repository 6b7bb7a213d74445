#!/usr/bin/env bash
# The Debian package, as a user gets it: `cpack -G DEB` of this build tree, then `dpkg -x` of the .deb
# into an empty directory, and pneufem run from there, outside the source and build trees.
#
# dpkg -x, not dpkg -i: it unpacks exactly the package's files into a prefix of the test's own,
# without touching the machine's package database (dpkg -i as root would install pneufem system-wide
# on a machine that other test runs share, and leave it there), and unlike `cmake --install --prefix`
# it tests the artifact itself, the .deb, with its control file. The package's Depends are checked
# to name packages that exist and are installed here (the libraries the unpacked binary then loads).
#
# Checks: the package's name, version and Depends (the libraries pneufem links: TBB, VTK, OpenVDB,
# CHOLMOD); the files (binary, example scenes, ParaView state, docs); `pneufem --version`; one small
# simulation of the installed example scene; and, when the package holds the Python module,
# `import pneufem` from the prefix.
# Usage: test_package.sh BUILD_DIR VERSION [WITH_PYTHON: 1 = the build has the Python module, so the package must]
set -uo pipefail
BUILD="$1"
VERSION="$2"
WITH_PYTHON="${3:-0}"
T="$(mktemp -d "${TMPDIR:-/tmp}/pneufem_package.XXXXXX")"
trap 'rm -rf "$T"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cpack -G DEB --config "$BUILD/CPackConfig.cmake" -B "$T/pkg" > "$T/cpack.log" 2>&1 || { cat "$T/cpack.log"; fail "cpack -G DEB"; }
deb=$(ls "$T"/pkg/*.deb 2>/dev/null | head -1)
[ -n "$deb" ] || fail "cpack made no .deb in $T/pkg"
[ "$(dpkg-deb -f "$deb" Package)" = pneufem ] || fail "package name"
[ "$(dpkg-deb -f "$deb" Version)" = "$VERSION" ] || fail "version $(dpkg-deb -f "$deb" Version), not $VERSION"
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for lib in libtbb12 libvtk9.1 libopenvdb10.0 libcholmod3 libnlopt0 libtomlplusplus3; do
  echo "$depends" | grep -q "\b$lib\b" || fail "Depends does not list $lib"
done
# Every dependency is a package this machine has installed (so they exist in Debian 12).
for dep in $(echo "$depends" | tr ',' '\n' | sed 's/(.*)//; s/|.*//' | tr -d ' '); do
  dpkg-query -W -f='${Status}' "$dep" 2>/dev/null | grep -q "install ok installed" || fail "dependency $dep is not an installed package"
done

mkdir "$T/root"
dpkg -x "$deb" "$T/root" || fail "dpkg -x"
P="$T/root/usr"
for f in bin/pneufem share/pneufem/examples/small_actuator.toml share/pneufem/examples/paper_story.toml \
         share/pneufem/paraview/open_run.py share/doc/pneufem/README.md share/doc/pneufem/docs/commands.md \
         share/doc/pneufem/docs/user_guide.md; do
  [ -f "$P/$f" ] || fail "the package has no /usr/$f"
done

# Run from an unrelated directory with a minimal environment: nothing from the build tree.
mkdir "$T/work" && cd "$T/work" || fail "cd"
out=$(env -i PATH=/usr/bin:/bin HOME="$T/work" "$P/bin/pneufem" --version 2>&1) || fail "pneufem --version: $out"
echo "$out" | grep -q "^$VERSION" || fail "pneufem --version printed '$out', not $VERSION"
env -i PATH=/usr/bin:/bin HOME="$T/work" "$P/bin/pneufem" simulate "$P/share/pneufem/examples/small_actuator.toml" \
  --set load.trials=1 --out run > sim.log 2>&1 || { cat sim.log; fail "the installed pneufem's simulation"; }
grep -q '"status": "ok"' run/summary.json || fail "summary.json has no \"status\": \"ok\""
[ "$(tail -n +2 run/angles.csv | wc -l)" -gt 3 ] || fail "angles.csv has no reports"
awk -F, 'NR > 1 && $4 > 1 { found = 1 } END { exit !found }' run/angles.csv || fail "the actuator did not bend (no angle above 1 deg)"

# The Python module, when the package holds one (python/CMakeLists.txt installs it).
pydir=$(find "$P/lib" -path '*python3*' -name 'pneufem*' -print -quit 2>/dev/null)
if [ -n "$pydir" ]; then
  site=$(dirname "$pydir")
  env -i PATH=/usr/bin:/bin PYTHONPATH="$site" /usr/bin/python3 -c "import pneufem; print(pneufem.__file__)" > py.log 2>&1 ||
    { cat py.log; fail "import pneufem from the package"; }
  grep -q "^$T/root" py.log || fail "import pneufem did not load the packaged module: $(cat py.log)"
elif [ "$WITH_PYTHON" = 1 ]; then
  fail "the build has the Python module (PNEUFEM_PYTHON) but the package holds none"
else
  echo "note: this build has no Python module (PNEUFEM_PYTHON off); import not tested"
fi
echo "PASS: $(basename "$deb") unpacked with dpkg -x; --version and a simulation of the installed example ran"
