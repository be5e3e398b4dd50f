#!/usr/bin/env python3
"""A real botlab LCM log written out as a ROS 2 bag (rosbag2, storage mcap) by rosbags' writer.

Independent of mbot_nav: the LCM log is parsed here from its published format (datasets/README.md:
records of sync word, event number, timestamp, channel, data; the legacy lidar_t, odometry_t and
pose_xyt_t types, big-endian after the 8-byte fingerprint), and rosbags serializes and writes the
bag. It is laid out as the ROS 2 MBot's is (mbot_ros2_ws):

  /tf_static  base_footprint → base_link (z 0.042), base_link → lidar_link (z 0.142, yaw 180°)
  /scan       sensor_msgs/LaserScan in lidar_link, binned onto uniform angles as sllidar does
              (NaN for empty bins); the RPLidar turns clockwise, so time runs against the index
              (time_increment < 0) and header.stamp is the scan's first beam in time
  /odom       nav_msgs/Odometry odom → base_footprint, from ODOMETRY
  /ground_truth  geometry_msgs/PoseStamped from TRUE_POSE (the motion capture)

Log times are the LCM log's event times; header stamps the messages' own utime.

    lcm_to_bag.py <log> <bag folder> [bins]
"""
import math
import shutil
import struct
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

ts = get_typestore(Stores.ROS2_JAZZY)
T = ts.types
log_path, bag_path = sys.argv[1], Path(sys.argv[2])
bins = int(sys.argv[3]) if len(sys.argv) > 3 else 400


def records(path):
    data = Path(path).read_bytes()
    pos = 0
    while pos + 28 <= len(data):
        sync, _event, t_us, clen, dlen = struct.unpack_from(">IqqII", data, pos)
        if sync != 0xEDA1DA01:
            raise SystemExit(f"{path}: no LCM sync word at byte {pos}")
        pos += 28
        channel = data[pos:pos + clen].decode()
        pos += clen
        yield t_us, channel, data[pos:pos + dlen]
        pos += dlen


def stamp(us):
    return T["builtin_interfaces/msg/Time"](sec=int(us // 1_000_000), nanosec=int(us % 1_000_000) * 1000)


def header(us, frame):
    return T["std_msgs/msg/Header"](stamp=stamp(us), frame_id=frame)


def quat_yaw(yaw):
    return T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def pose(x, y, yaw):
    return T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0), orientation=quat_yaw(yaw))


def transform(parent, child, z, yaw, us):
    return T["geometry_msgs/msg/TransformStamped"](
        header=header(us, parent), child_frame_id=child,
        transform=T["geometry_msgs/msg/Transform"](
            translation=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=z), rotation=quat_yaw(yaw)))


def laser_scan(payload):
    utime, n = struct.unpack_from(">qi", payload, 8)
    off = 20
    ranges = np.frombuffer(payload, ">f4", n, off).astype(np.float64)
    thetas = np.frombuffer(payload, ">f4", n, off + 4 * n).astype(np.float64)
    times = np.frombuffer(payload, ">i8", n, off + 8 * n)
    if n < 2:
        return None
    # lidar_t's thetas grow clockwise from the lidar's zero, which faces the robot's front: the beam's
    # counter-clockwise angle on the robot is -theta, and in lidar_link (turned 180°) -theta - pi.
    a = np.mod(-thetas, 2 * math.pi) - math.pi  # -theta - pi, wrapped to [-pi, pi)
    inc = 2 * math.pi / bins
    index = np.floor((a + math.pi) / inc + 0.5).astype(int) % bins
    binned = np.full(bins, np.nan, dtype=np.float32)
    bin_time = np.zeros(bins, dtype=np.int64)
    hit = (ranges > 0) & np.isfinite(ranges)
    for i in np.flatnonzero(hit):
        b = index[i]
        if math.isnan(binned[b]) or ranges[i] < binned[b]:
            binned[b] = ranges[i]
            bin_time[b] = times[i]
    # Time against the index, as a turning lidar's driver sets it: the direction the beams step
    # through the bins in time (their median step), the increment from the scan's span over the bins
    # stepped; the stamp is the first beam's time.
    order = np.argsort(times, kind="stable")
    steps = np.diff(index[order])
    steps = (steps + bins // 2) % bins - bins // 2
    stepped = int(np.abs(steps).sum())
    if stepped == 0:
        return None
    direction = 1 if np.median(steps) >= 0 else -1
    time_inc = direction * (times[order[-1]] - times[order[0]]) * 1e-6 / stepped
    first = order[0]
    # The beam at index i is at stamp + i*inc (inc > 0) or stamp + (bins-1-i)*|inc| (inc < 0).
    stamp_us = int(times[first] - (index[first] if time_inc > 0 else bins - 1 - index[first]) * abs(time_inc) * 1e6)
    scan = T["sensor_msgs/msg/LaserScan"](
        header=header(stamp_us, "lidar_link"), angle_min=-math.pi, angle_max=-math.pi + (bins - 1) * inc,
        angle_increment=inc, time_increment=time_inc, scan_time=abs(time_inc) * bins, range_min=0.15,
        range_max=12.0, ranges=binned, intensities=np.zeros(0, dtype=np.float32))
    return scan


if bag_path.exists():
    shutil.rmtree(bag_path)
counts = {}
with Writer(bag_path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
    conns = {
        "/tf_static": w.add_connection("/tf_static", "tf2_msgs/msg/TFMessage", typestore=ts),
        "/scan": w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts),
        "/odom": w.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts),
        "/ground_truth": w.add_connection("/ground_truth", "geometry_msgs/msg/PoseStamped", typestore=ts),
    }

    def write(topic, t_us, msg):
        w.write(conns[topic], int(t_us) * 1000, ts.serialize_cdr(msg, msg.__msgtype__))
        counts[topic] = counts.get(topic, 0) + 1

    first = True
    for t_us, channel, payload in records(log_path):
        if first:
            write("/tf_static", t_us, T["tf2_msgs/msg/TFMessage"](transforms=[
                transform("base_footprint", "base_link", 0.042, 0.0, t_us),
                transform("base_link", "lidar_link", 0.142, math.pi, t_us)]))
            first = False
        if channel == "LIDAR":
            scan = laser_scan(payload)
            if scan is not None:
                write("/scan", t_us, scan)
        elif channel in ("ODOMETRY", "TRUE_POSE") and len(payload) == 28:
            utime, x, y, theta = struct.unpack_from(">qfff", payload, 8)
            if channel == "ODOMETRY":
                write("/odom", t_us, T["nav_msgs/msg/Odometry"](
                    header=header(utime, "odom"), child_frame_id="base_footprint",
                    pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose(x, y, theta),
                                                                   covariance=np.zeros(36)),
                    twist=T["geometry_msgs/msg/TwistWithCovariance"](
                        twist=T["geometry_msgs/msg/Twist"](
                            linear=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                            angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)),
                        covariance=np.zeros(36))))
            else:
                write("/ground_truth", t_us, T["geometry_msgs/msg/PoseStamped"](
                    header=header(utime, "world"), pose=pose(x, y, theta)))
print(" ".join(f"{k} {v}" for k, v in sorted(counts.items())))
