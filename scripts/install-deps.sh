#!/usr/bin/env bash
# Installs the Debian 12 packages aortasph builds and runs with (needs root, or sudo); snakemake runs the
# studies (aortasph study, docs/studies.md).
set -euo pipefail
# Usage: scripts/install-deps.sh [--clang]; --clang adds clang with its sanitizer and OpenMP runtimes (the
# sanitizer and fuzzing builds of scripts/test.sh and scripts/fuzz.sh).
packages=(cmake g++ make pkg-config libeigen3-dev nlohmann-json3-dev catch2
          libosmesa6-dev libglm-dev libstb-dev libpng-dev fonts-dejavu-core ffmpeg
          python3-matplotlib snakemake)
if [ "${1:-}" = --clang ]; then packages+=(clang libclang-rt-14-dev libomp-14-dev); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
