#!/usr/bin/env bash
# Installs the Debian 12 packages pneufem needs (only those missing). Uses sudo when not root.
# slurm-wlm and munge: the test of `sweep --scheduler slurm` starts its own one-node SLURM (their
# system services stay unconfigured: Debian starts slurmctld/slurmd only with /etc/slurm/slurm.conf).
# universal-ctags: the test that no function is over 100 lines without a reason (tests/docs/check_long_functions.py).
set -euo pipefail
PKGS=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libtbb-dev libcli11-dev libtomlplusplus-dev
  libvtk9-dev libopenvdb-dev libboost-iostreams-dev
  libsuitesparse-dev libopenblas-dev libnlopt-cxx-dev
  libgtest-dev libgmock-dev nlohmann-json3-dev universal-ctags
  clang-14 libclang-rt-14-dev
  slurm-wlm munge
  python3-dev python3-pybind11 python3-numpy python3-matplotlib python3-pytest
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
