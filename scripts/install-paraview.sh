#!/usr/bin/env bash
# Installs ParaView 5.11 (Debian 12) for the user guide's ParaView step beside pneufem's build
# dependencies; pneufem itself does not need ParaView. Uses sudo when not root.
#
# Why not `apt-get install paraview`: it also installs python3-paraview (a recommended package),
# which conflicts with python3-vtk9, so apt REMOVES python3-vtk9 and libvtk9-dev, VTK's headers and
# CMake files that pneufem's build needs (the next configure stops at "Could not find a package
# configuration file provided by "VTK""). This script installs the paraview package without its
# recommends (the GUI, pvbatch and the libraries; nothing is removed), unpacks python3-paraview
# (pvpython and the modules of paraview.simple) into PREFIX instead of /usr, copies pvbatch beside
# pvpython there (each finds its Python modules relative to its own executable; with PYTHONPATH
# pointing there instead pvpython crashes), and writes two wrappers, pvpython and pvbatch, into BINDIR.
# Debian's ParaView renders through X only: on a machine without a display (no DISPLAY) the wrappers
# run it under xvfb-run, a virtual X server (package xvfb), and start it again when the server was
# not ready (about one start in ten here).
#
#   scripts/install-paraview.sh [PREFIX (default /opt/pneufem-paraview)] [BINDIR (default /usr/local/bin)]
#   pvpython viz/paraview/open_run.py out/first        # then, as in docs/user_guide.md
#
# To undo: rm -r PREFIX BINDIR/pvpython BINDIR/pvbatch; apt-get remove paraview.
set -euo pipefail
PREFIX=${1:-/opt/pneufem-paraview}
BINDIR=${2:-/usr/local/bin}
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

echo "install-paraview: paraview (without python3-paraview), xvfb, xauth"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends paraview xvfb xauth

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
chmod 755 "$work"  # apt-get download writes as the _apt user when it can
(cd "$work" && apt-get download -qq python3-paraview)
version=$(dpkg-query -W -f='${Version}' paraview)
deb=$(ls "$work"/python3-paraview_*.deb)
case "$deb" in
  *"_${version/*:/}_"*) ;;
  *) echo "install-paraview: $deb does not match paraview $version" >&2; exit 1 ;;
esac
echo "install-paraview: python3-paraview's modules into $PREFIX"
$SUDO mkdir -p "$PREFIX"
$SUDO dpkg-deb -x "$deb" "$PREFIX"
$SUDO cp /usr/bin/pvbatch3.11 "$PREFIX/usr/bin/pvbatch3.11"
$SUDO ln -sf pvbatch3.11 "$PREFIX/usr/bin/pvbatch"
for tool in pvpython pvbatch; do
  $SUDO tee "$BINDIR/$tool" > /dev/null <<EOF
#!/usr/bin/env bash
# Written by pneufem's scripts/install-paraview.sh: Debian's $tool beside python3-paraview's modules
# in $PREFIX (the package itself would remove libvtk9-dev). Debian's ParaView renders through X
# only: without a display this runs it under a virtual X server (xvfb-run), and again, up to three
# times, when the server was not ready for it ("bad X server connection": about one start in ten).
tool="$PREFIX/usr/bin/$tool"
if [ -n "\${DISPLAY:-}" ] || ! command -v xvfb-run > /dev/null; then exec "\$tool" "\$@"; fi
log=\$(mktemp)
trap 'rm -f "\$log"' EXIT
for attempt in 1 2 3; do
  xvfb-run -a -s "-screen 0 1920x1080x24" "\$tool" "\$@" 2> >(tee "\$log" >&2)
  status=\$?
  wait \$! 2> /dev/null
  grep -q "bad X server connection" "\$log" || exit \$status
  echo "$tool: the virtual X server was not ready (attempt \$attempt of 3)" >&2
done
exit \$status
EOF
  $SUDO chmod 755 "$BINDIR/$tool"
done
for tool in pvpython pvbatch; do
  "$BINDIR/$tool" -c "import paraview.simple" > /dev/null 2>&1 ||
    { echo "install-paraview: $BINDIR/$tool cannot import paraview.simple" >&2; exit 1; }
done
echo "install-paraview: $BINDIR/pvpython and $BINDIR/pvbatch (ParaView $version) import paraview.simple"
