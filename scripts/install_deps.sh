#!/usr/bin/env bash
# Installs the Debian 12 packages mbot_nav builds on. Safe to run twice: it only installs what is
# missing, and does nothing (not even `apt-get update`) when everything is already there.
#   scripts/install_deps.sh           what the build, the tests and the sanitizer build need
#   scripts/install_deps.sh --fuzz    also clang and its libFuzzer runtime (scripts/fuzz.sh)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libmrpt-dev libceres-dev liboctomap-dev
  liblcm-dev liblcm-bin libglib2.0-dev
  libopencv-dev libeigen3-dev
  libapriltag-dev  # libs/vision: the AprilTag reference detector (AprilRobotics 3.3)
  libgtest-dev libgmock-dev libbenchmark-dev
  zlib1g-dev
  clang-format  # scripts/check_format.sh (ctest format.check)
  iproute2    # the live LCM tests set up loopback multicast in a private network namespace
  nlohmann-json3-dev  # libs/sweep: the sweep manifest and the jobs' JSON outputs
  python3             # test scripts' small checks (tests/sweep/maze_sweep.sh)
  parallel            # sweeps on every local core (GNU parallel; tests/sweep)
  slurm-wlm munge     # sweeps as a Slurm job array: the test starts a one-node cluster (tests/sweep)
)

if [ "${1:-}" = --fuzz ]; then
  packages+=(clang libclang-rt-14-dev libomp-14-dev)
elif [ $# -gt 0 ]; then
  echo "install_deps: unknown argument '$1' (only --fuzz)" >&2
  exit 2
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install_deps: installing ${missing[*]}"
$SUDO apt-get update
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
