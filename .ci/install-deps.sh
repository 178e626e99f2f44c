#!/usr/bin/env bash
# Installs every Debian package that mneedle's build, tests and benchmarks need, and the report's
# npm packages (report/package-lock.json: three.js, esbuild, and playwright-core with pngjs for
# the browser test) with the machine's Node.js. Idempotent: what is already present is skipped;
# nothing is downloaded but Debian and npm-registry packages.
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
  chromium fonts-liberation libgl1-mesa-dri
  libopenmpi-dev openmpi-bin
  pybind11-dev pybind11-json-dev python3-dev python3-numpy python3-pytest python3-matplotlib
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The report's JavaScript packages, exactly as locked; again only when the lock changed.
report="$(cd "$(dirname "$0")/.." && pwd)/report"
# playwright-core (the browser test) needs Node.js 20; the machines this runs on carry it.
if ! command -v npm > /dev/null || ! command -v node > /dev/null; then
  echo "install-deps: node/npm not found: the HTML report needs Node.js 20 or later with npm" >&2
  exit 1
fi
node_major="$(node -p 'process.versions.node.split(".")[0]')"
if [ "$node_major" -lt 20 ]; then
  echo "install-deps: Node.js $(node --version) is too old: the report's tests need 20 or later" >&2
  exit 1
fi
if [ -f "$report/node_modules/.package-lock.json" ] &&
   [ "$report/node_modules/.package-lock.json" -nt "$report/package-lock.json" ]; then
  echo "install-deps: report/node_modules matches its lock file"
else
  # --ignore-scripts: esbuild finds its binary in its platform package; its postinstall only
  # checks that, and npm 11 would hold it back anyway.
  npm ci --prefix "$report" --no-audit --no-fund --ignore-scripts
fi
