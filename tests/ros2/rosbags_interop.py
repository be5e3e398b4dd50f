#!/usr/bin/env python3
"""Our CDR codec against rosbags (PyPI), an implementation we did not write.

For each message type of the MBot's generation, rosbags' typestore (ROS 2 Jazzy) builds a message
and serializes it; mbot_cdr_tool decodes those bytes and must give every field back. Then the tool
encodes the same message from JSON, and its bytes must equal rosbags' exactly (padding included)
and deserialize in rosbags to the same message. Truncated and corrupted payloads must be refused
with an error naming the offset, never a crash.

    rosbags_interop.py <mbot_cdr_tool> <work dir>
"""
import json
import math
import os
import subprocess
import sys

import numpy as np
from rosbags.typesys import Stores, get_typestore

ts = get_typestore(Stores.ROS2_JAZZY)
T = ts.types
tool, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)


def time(sec, ns):
    return T["builtin_interfaces/msg/Time"](sec=sec, nanosec=ns)


def header(sec, ns, frame):
    return T["std_msgs/msg/Header"](stamp=time(sec, ns), frame_id=frame)


def vec(x, y, z):
    return T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)


def quat(x, y, z, w):
    return T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)


def messages():
    yield "sensor_msgs/msg/LaserScan", T["sensor_msgs/msg/LaserScan"](
        header=header(1733140000, 123456789, "lidar_link"), angle_min=-3.1241, angle_max=3.1416,
        angle_increment=0.0175, time_increment=0.000138, scan_time=0.1, range_min=0.15, range_max=12.0,
        ranges=np.array([0.5, 1.25, 0.0, 11.9, 3.3, 2.0, 0.151], dtype=np.float32),
        intensities=np.array([47, 47, 0, 10, 47, 47, 20], dtype=np.float32))
    yield "nav_msgs/msg/Odometry", T["nav_msgs/msg/Odometry"](
        header=header(1733140001, 5, "odom"), child_frame_id="base_footprint",
        pose=T["geometry_msgs/msg/PoseWithCovariance"](
            pose=T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=1.5, y=-0.25, z=0.0),
                                             orientation=quat(0.0, 0.0, 0.3826834, 0.9238795)),
            covariance=np.arange(36, dtype=np.float64) * 0.01),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=vec(0.2, 0.0, 0.0), angular=vec(0.0, 0.0, -0.7)),
            covariance=np.arange(36, dtype=np.float64) * -0.5))
    yield "sensor_msgs/msg/Imu", T["sensor_msgs/msg/Imu"](
        header=header(7, 999999999, "base_link"), orientation=quat(0.01, -0.02, 0.7, 0.714),
        orientation_covariance=np.linspace(0, 1, 9), angular_velocity=vec(0.001, -0.002, 0.5),
        angular_velocity_covariance=np.full(9, 0.0004), linear_acceleration=vec(0.1, 0.2, 9.81),
        linear_acceleration_covariance=np.full(9, -1.0))
    yield "geometry_msgs/msg/Twist", T["geometry_msgs/msg/Twist"](linear=vec(0.25, 0, 0), angular=vec(0, 0, 1.5))
    ts_ = T["geometry_msgs/msg/TransformStamped"]
    tr = T["geometry_msgs/msg/Transform"]
    yield "tf2_msgs/msg/TFMessage", T["tf2_msgs/msg/TFMessage"](transforms=[
        ts_(header=header(10, 20, "odom"), child_frame_id="base_footprint",
            transform=tr(translation=vec(1, 2, 0), rotation=quat(0, 0, 0.1, 0.995))),
        ts_(header=header(10, 20, "base_link"), child_frame_id="lidar_link",
            transform=tr(translation=vec(0, 0, 0.14179), rotation=quat(0, 0, 0.99999, 0.0008)))])


def plain(m):
    """A rosbags message as JSON-like data (numpy arrays as lists)."""
    if isinstance(m, np.ndarray):
        return [float(v) for v in m]
    if isinstance(m, list):
        return [plain(v) for v in m]
    if hasattr(m, "__dataclass_fields__"):
        return {k: plain(getattr(m, k)) for k in m.__dataclass_fields__ if k != "__msgtype__"}
    return m


failures = []


def same(a, b, where):
    if isinstance(a, dict):
        if set(a) != set(b):
            failures.append(f"{where}: fields {sorted(a)} against {sorted(b)}")
            return
        for k in a:
            same(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        if len(a) != len(b):
            failures.append(f"{where}: {len(a)} elements against {len(b)}")
            return
        for i, (u, v) in enumerate(zip(a, b)):
            same(u, v, f"{where}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        if not math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=1e-9):
            failures.append(f"{where}: {a} against {b}")
    elif a != b:
        failures.append(f"{where}: {a!r} against {b!r}")


def run(*args):
    return subprocess.run([tool, *args], capture_output=True, text=True)


for typename, msg in messages():
    name = typename.split("/")[-1]
    theirs = bytes(ts.serialize_cdr(msg, typename))
    path = os.path.join(work, name + ".cdr")
    open(path, "wb").write(theirs)
    # rosbags wrote it, we read it.
    r = run("decode", typename, path)
    if r.returncode != 0:
        failures.append(f"{typename}: our decoder refused rosbags' bytes: {r.stderr.strip()}")
        continue
    same(json.loads(r.stdout), plain(msg), name)
    # We write it, rosbags reads it, and the bytes are the same.
    jpath = os.path.join(work, name + ".json")
    json.dump(plain(msg), open(jpath, "w"))
    ours_path = os.path.join(work, name + ".ours.cdr")
    r = run("encode", typename, jpath, ours_path)
    if r.returncode != 0:
        failures.append(f"{typename}: our encoder failed: {r.stderr.strip()}")
        continue
    ours = open(ours_path, "rb").read()
    if ours != theirs:
        first = next((i for i, (u, v) in enumerate(zip(ours, theirs)) if u != v), min(len(ours), len(theirs)))
        failures.append(f"{typename}: our {len(ours)} bytes differ from rosbags' {len(theirs)} from byte {first}")
    same(plain(ts.deserialize_cdr(ours, typename)), plain(msg), name + " (rosbags reading ours)")
    # Cut short anywhere: refused, naming an offset.
    for cut in sorted({4, len(theirs) // 3, len(theirs) // 2, len(theirs) - 1}):
        bad = os.path.join(work, f"{name}.cut{cut}.cdr")
        open(bad, "wb").write(theirs[:cut])
        r = run("decode", typename, bad)
        if r.returncode != 1 or "offset" not in r.stderr:
            failures.append(f"{typename} cut at {cut} bytes: exit {r.returncode}, {r.stderr.strip()!r}")
    print(f"{typename}: {len(theirs)} bytes; read, written byte for byte, truncations refused")

# A LaserScan whose ranges claim a billion floats: refused without allocating them.
scan = bytearray(open(os.path.join(work, "LaserScan.cdr"), "rb").read())
count_at = 4 + 4 + 4 + 4 + len("lidar_link") + 1
count_at += (4 - (count_at - 4) % 4) % 4 + 7 * 4
scan[count_at:count_at + 4] = (1_000_000_000).to_bytes(4, "little")
bad = os.path.join(work, "LaserScan.huge.cdr")
open(bad, "wb").write(scan)
r = run("decode", "sensor_msgs/msg/LaserScan", bad)
if r.returncode != 1 or "ranges counts 1000000000" not in r.stderr:
    failures.append(f"a billion ranges: exit {r.returncode}, {r.stderr.strip()!r}")
else:
    print("a billion ranges: refused (" + r.stderr.strip() + ")")

for f in failures:
    print("FAIL: " + f)
print("PASS: CDR against rosbags" if not failures else f"{len(failures)} failures")
sys.exit(1 if failures else 0)
