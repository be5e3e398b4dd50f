#!/usr/bin/env python3
"""Our MCAP reader against Foxglove's own writer (`mcap` from PyPI), with CDR from rosbags.

Writes bags the way rosbag2 lays them out (profile ros2, ros2msg schemas, cdr messages,
offered_qos_profiles) in every form the writer has — chunks uncompressed, zstd and lz4, several
chunks, no chunks at all, data CRCs on — and checks that mbot_mcap_tool reads every message in order
with its channel, times and decoded fields. Then bad files: cut short (what came before the cut is
read, and the cut is said), a flipped bit in a chunk (its CRC), no magic.

    mcap_interop.py <mbot_mcap_tool> <work dir>
"""
import json
import math
import os
import subprocess
import sys

import numpy as np
from mcap.writer import CompressionType, Writer
from rosbags.typesys import Stores, get_typestore

ts = get_typestore(Stores.ROS2_JAZZY)
T = ts.types
tool, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
QOS = ("- history: keep_last\n  depth: 10\n  reliability: reliable\n  durability: volatile\n"
       "  deadline:\n    sec: 9223372036\n    nsec: 854775807\n")


def header(t_ns, frame):
    return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9),
                                    frame_id=frame)


def scan(i, t_ns):
    ranges = np.array([0.5 + 0.01 * i + 0.1 * k for k in range(360)], dtype=np.float32)
    return T["sensor_msgs/msg/LaserScan"](
        header=header(t_ns, "lidar_link"), angle_min=-math.pi, angle_max=math.pi, angle_increment=2 * math.pi / 360,
        time_increment=0.0, scan_time=0.1, range_min=0.15, range_max=12.0, ranges=ranges,
        intensities=np.zeros(360, dtype=np.float32))


def odom(i, t_ns):
    yaw = 0.01 * i
    pose = T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=0.02 * i, y=0.0, z=0.0),
                                       orientation=T["geometry_msgs/msg/Quaternion"](
                                           x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)))
    zero = T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    return T["nav_msgs/msg/Odometry"](
        header=header(t_ns, "odom"), child_frame_id="base_footprint",
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)))


def write(path, **options):
    """10 s of a robot: /scan at 10 Hz, /odom at 25 Hz, in time order. Returns what was written."""
    expected = []
    with open(path, "wb") as f:
        w = Writer(f, **options)
        w.start(profile="ros2", library="mbot_nav tests (mcap " + "python)")
        s_scan = w.register_schema("sensor_msgs/msg/LaserScan", "ros2msg", b"std_msgs/Header header\nfloat32 angle_min\n")
        s_odom = w.register_schema("nav_msgs/msg/Odometry", "ros2msg", b"std_msgs/Header header\n")
        c_scan = w.register_channel("/scan", "cdr", s_scan, {"offered_qos_profiles": QOS})
        c_odom = w.register_channel("/odom", "cdr", s_odom, {"offered_qos_profiles": QOS})
        events = [(1_733_140_000_000_000_000 + i * 100_000_000, "/scan", i) for i in range(100)]
        events += [(1_733_140_000_000_000_000 + i * 40_000_000 + 1, "/odom", i) for i in range(250)]
        for seq, (t, topic, i) in enumerate(sorted(events)):
            if topic == "/scan":
                data = ts.serialize_cdr(scan(i, t), "sensor_msgs/msg/LaserScan")
                w.add_message(c_scan, log_time=t, data=bytes(data), publish_time=t, sequence=seq)
                expected.append({"topic": topic, "log_time": t, "sequence": seq, "i": i})
            else:
                data = ts.serialize_cdr(odom(i, t), "nav_msgs/msg/Odometry")
                w.add_message(c_odom, log_time=t, data=bytes(data), publish_time=t + 5, sequence=seq)
                expected.append({"topic": topic, "log_time": t, "sequence": seq, "i": i})
        w.finish()
    return expected


def read(path):
    r = subprocess.run([tool, path], capture_output=True, text=True)
    return r.returncode, (json.loads(r.stdout) if r.returncode == 0 else r.stderr.strip())


failures = []


def check(ok, what):
    print(("PASS: " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)


def matches(got, expected, n=None):
    """Every message got is the expected one at its place: topic, times, sequence, fields."""
    if n is None and len(got) != len(expected):
        return f"{len(got)} messages, {len(expected)} written"
    for g, e in zip(got, expected):
        if (g["topic"], g["log_time"], g["sequence"]) != (e["topic"], e["log_time"], e["sequence"]):
            return f"message {e['sequence']}: {g['topic']} {g['log_time']} against {e['topic']} {e['log_time']}"
        if e["topic"] == "/scan":
            if g["frame_id"] != "lidar_link" or len(g["ranges"]) != 360 or \
                    not math.isclose(g["ranges"][7], 0.5 + 0.01 * e["i"] + 0.7, rel_tol=1e-6):
                return f"scan {e['i']}: fields differ"
        elif not (math.isclose(g["x"], 0.02 * e["i"], abs_tol=1e-12) and math.isclose(g["yaw"], 0.01 * e["i"], abs_tol=1e-9)):
            return f"odometry {e['i']}: x {g['x']}, yaw {g['yaw']}"
    return None


cases = {
    "zstd": dict(compression=CompressionType.ZSTD, chunk_size=64 * 1024),
    "lz4": dict(compression=CompressionType.LZ4, chunk_size=64 * 1024),
    "uncompressed": dict(compression=CompressionType.NONE, chunk_size=64 * 1024, enable_data_crcs=True),
    "one_chunk": dict(compression=CompressionType.ZSTD, chunk_size=64 * 1024 * 1024),
    "no_chunks": dict(use_chunking=False, enable_data_crcs=True),
}
for name, options in cases.items():
    path = os.path.join(work, name + ".mcap")
    expected = write(path, **options)
    rc, out = read(path)
    if rc != 0:
        check(False, f"{name}: refused: {out}")
        continue
    st = out["stats"]
    topics = {c["topic"]: (c["message_encoding"], c["schema"], c["schema_encoding"]) for c in out["channels"]}
    qos = all(c["metadata"].get("offered_qos_profiles") == QOS for c in out["channels"])
    problem = matches(out["messages"], expected)
    check(problem is None and out["profile"] == "ros2" and st["footer"] and not st["truncated"] and qos and
          topics == {"/scan": ("cdr", "sensor_msgs/msg/LaserScan", "ros2msg"),
                     "/odom": ("cdr", "nav_msgs/msg/Odometry", "ros2msg")},
          f"{name}: {len(out['messages'])} messages in order, fields decoded, {st['chunks']} chunks, "
          f"{st['crcs_checked']} CRCs checked ({problem or 'all as written'})")

# Cut short at 60 %: what came before the cut is read, the cut is said, nothing crashes.
whole = open(os.path.join(work, "zstd.mcap"), "rb").read()
expected = write(os.path.join(work, "zstd.mcap"), **cases["zstd"])
cut = os.path.join(work, "cut.mcap")
open(cut, "wb").write(whole[: len(whole) * 6 // 10])
rc, out = read(cut)
check(rc == 0 and out["stats"]["truncated"] and 0 < len(out["messages"]) < len(expected) and
      matches(out["messages"], expected, n=len(out["messages"])) is None,
      f"cut at 60 %: {len(out['messages']) if rc == 0 else out} messages read, truncated said")
# Cut at every 997th byte: never a crash, never an exit but 0 (a prefix) or 1 (an error named).
codes = set()
for n in range(0, len(whole), 997):
    open(cut, "wb").write(whole[:n])
    codes.add(subprocess.run([tool, cut], capture_output=True).returncode)
check(codes <= {0, 1}, f"cut at every 997th byte: exits {sorted(codes)}")
# A flipped bit inside an uncompressed chunk: its CRC.
raw = bytearray(open(os.path.join(work, "uncompressed.mcap"), "rb").read())
raw[len(raw) // 3] ^= 0x10
bad = os.path.join(work, "flipped.mcap")
open(bad, "wb").write(raw)
rc, out = read(bad)
check(rc == 1 and "CRC" in out and "at byte" in out, f"a flipped bit: refused ({out if rc else 'read'})")
# Not MCAP at all.
open(bad, "wb").write(b"#ROSBAG V2.0\n" + bytes(100))
rc, out = read(bad)
check(rc == 1 and "not an MCAP file" in out, f"a ROS 1 bag: refused ({out if rc else 'read'})")

print("PASS: MCAP against Foxglove's writer" if not failures else f"{len(failures)} failures")
sys.exit(1 if failures else 0)
