#!/usr/bin/env bash
# Installs what is missing (Debian 12 packages), then configures and builds mbot_nav in ./build.
# Safe to run again: it only installs what is missing and rebuilds what changed.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi  # build warnings are errors in CI
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DMBOT_WERROR=$werror ${MBOT_CMAKE_ARGS:-}
cmake --build build
