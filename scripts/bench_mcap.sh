#!/usr/bin/env bash
# MCAP read throughput (BENCHMARKS.md, "ROS 2 bags"): the Intel log's ROS 1 bag converted to a
# rosbag2 MCAP bag (zstd chunks) by rosbags-convert, then read by our `mcap` source (Google
# Benchmark), Foxglove's Python reader with mcap-ros2-support, and rosbags, in one run.
#   scripts/bench_mcap.sh [runs (default 3)] [out_dir (default out/bench_mcap)]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
out=${2:-out/bench_mcap}
datasets=${MBOT_DATASETS_DIR:-$PWD/../shared/datasets}
venv=tests/ros2/.venv
[ -x build/tests/mbot_ros2_benchmark ] || { echo "bench_mcap.sh: build first (scripts/build.sh)" >&2; exit 1; }
[ -x $venv/bin/python ] || { echo "bench_mcap.sh: no $venv (scripts/install_deps.sh makes it)" >&2; exit 1; }
mkdir -p "$out"
bag="$out/intel_zstd"
if [ ! -f "$bag/metadata.yaml" ]; then
  rm -rf "$bag"
  $venv/bin/rosbags-convert --src "$datasets/carmen/intel.orig.bag" --dst "$bag" --dst-storage mcap \
    --compress zstd --compress-mode storage
fi
$venv/bin/python tests/ros2/bench_mcap.py build/tests/mbot_ros2_benchmark "$bag" "$runs"
