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
  libwebsocketpp-dev libboost-system-dev  # libs/viewer: the Foxglove WebSocket server and the page
  chromium            # tests/viewer: the page in a real (headless) browser
  python3-venv        # tests/ros2: rosbags and mcap (PyPI) in a venv, the independent peers
  libzstd-dev liblz4-dev  # libs/ros2: MCAP chunks compressed with zstd or lz4
  libbz2-dev          # libs/ros2: ROS 1 bags' bz2 chunks
  cyclonedds-dev      # libs/ros2: ROS 2 on the wire (Eclipse Cyclone DDS, rmw_cyclonedds_cpp's DDS)
  libfastrtps-dev libfastcdr-dev fastddsgen  # tests/ros2: the other DDS vendor plays the robot
)
# tests/viewer's peers run on Node.js: the machine's own when it has one, else Debian's.
if ! command -v node > /dev/null || ! command -v npm > /dev/null; then packages+=(nodejs npm); fi

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

# The viewer tests' peers from npm (Foxglove's protocol client and schemas, puppeteer-core, ws,
# ajv), pinned by tests/viewer/package-lock.json, in tests/viewer/node_modules; again only when the
# lock file changed since the last install.
install_test_peers() {
  local root dir venv
  root="$(cd "$(dirname "$0")/.." && pwd)"
  dir="$root/tests/viewer"
  if ! { [ -f "$dir/node_modules/.installed" ] && cmp -s "$dir/package-lock.json" "$dir/node_modules/.installed"; }; then
    echo "install_deps: installing the viewer tests' npm packages in $dir/node_modules"
    (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error) && cp "$dir/package-lock.json" "$dir/node_modules/.installed"
  fi
  # tests/ros2: rosbags and what it needs, pinned, in a venv of Debian's python3.
  venv="$root/tests/ros2/.venv"
  if ! { [ -f "$venv/.installed" ] && cmp -s "$root/tests/ros2/requirements.txt" "$venv/.installed"; }; then
    echo "install_deps: installing the ROS 2 tests' Python packages in $venv"
    rm -rf "$venv"
    /usr/bin/python3 -m venv "$venv" && "$venv/bin/pip" install --quiet --disable-pip-version-check \
      -r "$root/tests/ros2/requirements.txt" && cp "$root/tests/ros2/requirements.txt" "$venv/.installed"
  fi
}

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages already installed"
  install_test_peers
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install_deps: installing ${missing[*]}"
$SUDO apt-get update
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
install_test_peers
