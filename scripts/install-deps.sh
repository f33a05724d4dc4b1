#!/usr/bin/env bash
# Installs the Debian packages sanguis needs. Idempotent: when every package is
# already present it does nothing (no apt-get update, no network).
#   scripts/install-deps.sh            build + test + validation plots (python3-vtk9: the
#                                      tests read the flow frames through VTK's readers)
#   scripts/install-deps.sh --bench    also the peer codes used by bench/ (LAMMPS, Gerris)
#   scripts/install-deps.sh --clang    also Clang and its OpenMP runtime (CXX=clang++ builds)
set -euo pipefail

packages=(
  g++ cmake ninja-build make pkg-config
  libeigen3-dev libtomlplusplus-dev libcli11-dev libgtest-dev
  libp4est-dev libopenmpi-dev openmpi-bin
  python3 python3-numpy python3-matplotlib python3-vtk9
)
case "${1:-}" in
  --bench) packages+=(lammps gerris) ;;
  --clang) packages+=(clang libomp-dev) ;;
  "") ;;
  *) echo "install-deps: unknown option '$1' (expected --bench or --clang)" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
