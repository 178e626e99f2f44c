#!/usr/bin/env bash
# Installs every Debian package that mneedle's build, tests and benchmarks need.
# Idempotent: packages already present are skipped; nothing is downloaded but Debian packages.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libassimp-dev
  libeigen3-dev
  libnlopt-cxx-dev libnlopt-dev
  libsuitesparse-dev libopenblas-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 libclang-rt-14-dev
  nlohmann-json3-dev libcli11-dev libtomlplusplus-dev libfmt-dev
  libplplot-dev
  libssl-dev
  python3-meshio
  calculix-ccx
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
