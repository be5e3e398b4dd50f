#!/usr/bin/env python3
"""Real robot data as a ROS 2 bag, written by rosbags, replayed through our `mcap` source.

1. A botlab LCM log with motion capture (sweep_drive_square_10mx10m_5cm.log) becomes a rosbag2
   MCAP bag laid out as the ROS 2 MBot's (lcm_to_bag.py: /scan binned onto uniform angles with NaN
   for empty bins, the lidar turned 180° on /tf_static, /odom, /ground_truth). SLAM on the bag
   (config/ros2_replay.ini) and on the LCM log (config/slam_replay.ini) must score within 1 cm of
   each other against the motion capture, on the same scans, with the lidar's mount read from
   /tf_static.
2. The Intel log as a ROS 1 bag made by another project (carmen/intel.orig.bag), converted to a
   rosbag2 MCAP bag by rosbags-convert (zstd-compressed chunks), replays with every scan and every
   odometry message: the counts rosbags' own reader gives.
3. Both Intel ROS 1 bags read directly (our ros1_bag source): rosbags' counts, and for the first
   the same scans and odometry as through rosbags-convert's MCAP.

    bag_replay_test.py <mbot_nav> <config dir> <work dir>     (MBOT_DATASETS_DIR: the datasets)
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader

mbot_nav, config, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
datasets = Path(os.environ.get("MBOT_DATASETS_DIR", ""))
here = Path(__file__).resolve().parent
log = datasets / "botlab/legacy_2017/sweep_drive_square_10mx10m_5cm.log"
ros1 = datasets / "carmen/intel.orig.bag"
if not log.exists() or not ros1.exists():
    print(f"SKIPPED: the datasets are not at {datasets} (MBOT_DATASETS_DIR)")
    sys.exit(1 if os.environ.get("CI") == "true" else 77)
if work.exists():
    shutil.rmtree(work)
work.mkdir(parents=True)
failures = []


def check(ok, what):
    print(("ok: " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)


def run(args):
    p = subprocess.run([mbot_nav, *args, "--set", "pipeline.progress=off"], capture_output=True, text=True)
    out = p.stdout + p.stderr
    if p.returncode != 0:
        print(out)
        raise SystemExit(f"FAIL: mbot_nav {' '.join(args)} exited {p.returncode}")
    return out


# 1. The LCM log as a ROS 2 bag.
bag = work / "drive_square_bag"
subprocess.run([sys.executable, here / "lcm_to_bag.py", log, bag], check=True)
out_bag = run(["--config", config / "ros2_replay.ini", "--set", f"source.path={bag}",
               "--set", f"output.dir={work / 'from_bag'}"])
out_lcm = run(["--config", config / "slam_replay.ini", "--set", f"source.path={log}",
               "--set", f"output.dir={work / 'from_lcm'}"])
m_bag = json.loads((work / "from_bag/metrics.json").read_text())
m_lcm = json.loads((work / "from_lcm/metrics.json").read_text())
ate_bag = m_bag["slam_ate"]["aligned"]["xy_m"]["rmse"]
ate_lcm = m_lcm["slam_ate"]["aligned"]["xy_m"]["rmse"]
print(f"SLAM against the motion capture: from the bag {ate_bag:.4f} m, from the LCM log {ate_lcm:.4f} m (RMSE xy)")
check(abs(ate_bag - ate_lcm) <= 0.01, f"the bag's SLAM error is within 1 cm of the LCM log's ({ate_bag - ate_lcm:+.4f} m)")
check(m_bag["scans"] == m_lcm["scans"], f"the same scans: {m_bag['scans']} from the bag, {m_lcm['scans']} from the log")
check(m_bag["slam_ate"]["aligned"]["samples"] >= m_lcm["slam_ate"]["aligned"]["samples"] - 2,
      "scored against the bag's /ground_truth on as many scans")
run(["--config", config / "inspect.ini", "--set", f"source.path={bag}", "--set", f"output.dir={work / 'bag_inspect'}"])
details = json.loads((work / "bag_inspect/inspect.json").read_text())["details"]
mount = details.get("lidar lidar_link", "")
print("lidar mount as the source read it:", mount or "(not reported)")
check("yaw 180.0 deg" in mount and "x 0.000 m, y 0.000 m" in mount and "/tf_static" in mount,
      "the lidar's mount (180° yaw) came from /tf_static")

# 2. A ROS 1 bag of another project, converted by rosbags-convert.
intel = work / "intel_mcap"
subprocess.run([here / ".venv/bin/rosbags-convert", "--src", ros1, "--dst", intel, "--dst-storage", "mcap",
                "--compress", "zstd", "--compress-mode", "storage"], check=True)
counts = {}
with AnyReader([intel]) as reader:
    for connection in reader.connections:
        counts[connection.topic] = counts.get(connection.topic, 0) + connection.msgcount
print("rosbags reads", counts)
run(["--config", config / "inspect.ini", "--set", f"source.path={intel}", "--set", f"output.dir={work / 'intel_inspect'}"])
inspected = json.loads((work / "intel_inspect/inspect.json").read_text())
for topic, channel in (("/scan", "LIDAR"), ("/odom", "MBOT_ODOMETRY")):
    n = inspected["channels"].get(channel, {}).get("count")
    check(n == counts.get(topic), f"{topic}: {n} events from our source, {counts.get(topic)} messages by rosbags")
check(inspected["rejected_messages"] == 0 and not inspected["truncated_tail"], "nothing rejected, no truncation")
check(inspected["channels"]["LIDAR"]["beams_min"] == 180, "180 beams per Intel scan")

# 3. The ROS 1 bags themselves (rosbag format 2.0, bz2 chunks), read by our ros1_bag source: every
#    message rosbags' ROS 1 reader counts, and the same scans and odometry as the MCAP that
#    rosbags-convert made of the same bag.
from rosbags.rosbag1 import Reader as Ros1Reader  # noqa: E402

for name in ("intel.orig.bag", "intel.clf2bag.bag"):
    path = datasets / "carmen" / name
    with Ros1Reader(path) as reader:
        counts1 = {}
        for c in reader.connections:
            counts1[c.topic] = counts1.get(c.topic, 0) + c.msgcount
    out = work / f"inspect_{name}"
    run(["--config", config / "inspect.ini", "--set", f"source.path={path}", "--set", f"output.dir={out}"])
    direct = json.loads((out / "inspect.json").read_text())
    check(direct["format"] == "ROS 1 bag", f"{name}: read as a ROS 1 bag ({direct['format']})")
    for topic, channel in (("/scan", "LIDAR"), ("/odom", "MBOT_ODOMETRY")):
        n = direct["channels"].get(channel, {}).get("count")
        check(n == counts1.get(topic), f"{name} {topic}: {n} events, {counts1.get(topic)} messages by rosbags")
    check(direct["rejected_messages"] == 0 and not direct["truncated_tail"], f"{name}: nothing rejected, not cut")
    if name == "intel.orig.bag":
        for channel, keys in (("LIDAR", ("beams_min", "beams_max", "range_min_m", "range_max_m", "returns",
                                         "no_returns", "first_s", "last_s")),
                              ("MBOT_ODOMETRY", ("path_m", "first_s", "last_s"))):
            a, b = direct["channels"][channel], inspected["channels"][channel]
            same = all(a.get(k) == b.get(k) for k in keys)
            check(same, f"{name} {channel}: the same as through rosbags-convert's MCAP "
                        f"({', '.join(f'{k} {a.get(k)}' for k in keys)})")

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("PASS")
