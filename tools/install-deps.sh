#!/usr/bin/env bash
# Installs what drape needs to build, test and benchmark on Debian 12, and only what is missing.
# Run as root (or with sudo available). Used by `make deps`; safe to run again.
set -euo pipefail

packages=(
  cmake make g++ lld pkg-config git ca-certificates
  clang-14 libclang-rt-14-dev clang-format clang-tidy   # fuzzing (libFuzzer) and the style configs
  libeigen3-dev libsuitesparse-dev nlohmann-json3-dev libfmt-dev libcli11-dev
  libblas-dev liblapack-dev libopenblas0-pthread        # dense kernels (CHOLMOD, the solver): OpenBLAS 3x the reference
  libtinygltf-dev libtinyobjloader-dev libstb-dev
  libembree-dev libtbb-dev libcgal-dev libgmp-dev libmpfr-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libbullet-dev                                         # the peer engine benchmarked beside drape
  libassimp-dev zlib1g-dev                              # FBX motions (Mixamo's format)
  nodejs npm                                            # the Khronos glTF validator, the web page's three.js
  libcpp-httplib-dev libhiredis-dev redis-server        # drape serve: HTTP, the shared Redis queue
  chromium                                              # the web page's browser test (headless)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# nodejs/npm may come from elsewhere than Debian (e.g. a preinstalled Node): accept working commands.
if command -v node >/dev/null && command -v npm >/dev/null; then
  filtered=()
  for p in "${missing[@]}"; do [[ "$p" == nodejs || "$p" == npm ]] || filtered+=("$p"); done
  missing=("${filtered[@]}")
fi

if ((${#missing[@]})); then
  echo "make deps: installing ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "make deps: Debian packages present"
fi

# The Khronos glTF validator (npm package gltf-validator), pinned in tools/package.json.
here=$(cd "$(dirname "$0")" && pwd)
if [[ ! -d "$here/node_modules/gltf-validator" ]]; then
  echo "make deps: installing gltf-validator (npm)"
  (cd "$here" && npm install --no-audit --no-fund --silent)
fi

# The web page's three.js and the browser test's puppeteer-core, pinned in web/package-lock.json;
# drape serve serves web/node_modules/three itself (no CDN).
if [[ ! -d "$here/../web/node_modules/three" || ! -d "$here/../web/node_modules/puppeteer-core" ]]; then
  echo "make deps: installing the web page's packages (npm)"
  (cd "$here/../web" && npm ci --no-audit --no-fund --silent)
fi
