#!/usr/bin/env python3
"""The bags mbot_nav records (--set record.format=mcap), opened by readers we did not write.

1. SLAM on a real botlab log, recorded: Foxglove's `mcap` reader checks every CRC (chunks, data
   section, summary) and `mcap-ros2-support` decodes every message from the schemas we wrote;
   rosbags opens the folder (metadata.yaml) and deserializes every message with its own Jazzy
   types. Counts agree with metadata.yaml and the MCAP summary; the profile, encodings, QoS and
   the rosbag2 metadata record are as rosbag2 writes them; the content is the run's (the scans, the
   last pose of slam.tum, the map's size).
2. The simulated Maze Explorer stopped with Ctrl-C a few seconds in: the bag is still whole.
3. Heavy Lift's camera tags, as apriltag_ros publishes them: /detections and the tags on /tf.

    recorder_interop.py <mbot_nav> <config dir> <work dir>   (MBOT_DATASETS_DIR: the datasets)
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from ruamel.yaml import YAML

mbot_nav, config, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
datasets = Path(os.environ.get("MBOT_DATASETS_DIR", ""))
log = datasets / "botlab/legacy_2017/sweep_drive_square_10mx10m_5cm.log"
if work.exists():
    shutil.rmtree(work)
work.mkdir(parents=True)
failures = []


def check(ok, what):
    print(("ok: " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)


def open_with_foxglove(bag):
    """Every record through Foxglove's reader with CRC checks; every message decoded."""
    counts, decoded = {}, {}
    with open(bag / "run.mcap", "rb") as f:
        reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        summary = reader.get_summary()
        for schema, channel, message, ros_msg in reader.iter_decoded_messages(log_time_order=False):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            decoded[channel.topic] = ros_msg  # the last one
        metadata = list(reader.iter_metadata())
    return header, summary, counts, decoded, metadata


def open_with_rosbags(bag):
    ts = get_typestore(Stores.ROS2_JAZZY)
    # The MBot's own message, from mbot_interfaces/msg/Encoders.msg of the firmware's generation.
    ts.register(get_types_from_msg("builtin_interfaces/Time stamp\nint64[3] ticks\nint32[3] delta_ticks\n"
                                   "int32 delta_time\n", "mbot_interfaces/msg/Encoders"))
    ts.register(get_types_from_msg("float32[3] velocity\n", "mbot_interfaces/msg/MotorVelocity"))
    counts, last, qos = {}, {}, {}
    with AnyReader([bag], default_typestore=ts) as reader:
        for connection, _t, raw in reader.messages():
            msg = reader.deserialize(raw, connection.msgtype)
            counts[connection.topic] = counts.get(connection.topic, 0) + 1
            last[connection.topic] = msg
        for c in reader.connections:
            qos[c.topic] = c.ext.offered_qos_profiles
    return counts, last, qos


# 1. SLAM on a real log, recorded.
if not log.exists():
    print(f"SKIPPED: the datasets are not at {datasets} (MBOT_DATASETS_DIR)")
    sys.exit(1 if os.environ.get("CI") == "true" else 77)
bag = work / "slam"
p = subprocess.run([mbot_nav, "--config", config / "slam_replay.ini", "--set", f"output.dir={bag}",
                    "--set", "pipeline.progress=off", "--set", "record.format=mcap",
                    "--set", "slam.publish_particles_every=5"], capture_output=True, text=True)
print(p.stdout[-600:] + p.stderr[-600:])
check(p.returncode == 0, f"the recorded SLAM run exited 0 ({p.returncode})")
meta = YAML(typ="safe").load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
header, summary, fox_counts, fox_last, fox_meta = open_with_foxglove(bag)
check(header.profile == "ros2", f"MCAP profile ros2 ({header.profile!r})")
check(all(s.encoding == "ros2msg" for s in summary.schemas.values()), "every schema is ros2msg")
check(all(c.message_encoding == "cdr" for c in summary.channels.values()), "every channel is cdr")
check(all("offered_qos_profiles" in c.metadata for c in summary.channels.values()),
      "every channel has offered_qos_profiles")
check(len(summary.chunk_indexes) > 0 and summary.statistics.message_count == sum(fox_counts.values()),
      f"summary: {len(summary.chunk_indexes)} chunks indexed, statistics count {summary.statistics.message_count} = "
      f"{sum(fox_counts.values())} messages decoded by mcap-ros2-support")
names = [m.name for m in fox_meta]
check("rosbag2" in names and "serialized_metadata" in fox_meta[names.index("rosbag2")].metadata,
      "the rosbag2 metadata record holds serialized_metadata")
rb_counts, rb_last, rb_qos = open_with_rosbags(bag)
print("topics:", ", ".join(f"{t} {n}" for t, n in sorted(rb_counts.items())))
check(rb_counts == fox_counts, "rosbags and Foxglove's reader read the same messages")
meta_counts = {t["topic_metadata"]["name"]: t["message_count"] for t in meta["topics_with_message_count"]}
check(meta_counts == rb_counts and meta["message_count"] == sum(rb_counts.values()),
      "metadata.yaml's counts are what the file holds")
check(meta["version"] == 9 and meta["storage_identifier"] == "mcap" and meta["relative_file_paths"] == ["run.mcap"],
      "metadata.yaml: version 9, storage mcap, run.mcap")
for topic in ("/scan", "/odom", "/tf", "/tf_static", "/estimated_pose", "/map", "/particle_cloud", "/ground_truth"):
    check(rb_counts.get(topic, 0) > 0, f"{topic} recorded ({rb_counts.get(topic, 0)})")
check(rb_qos["/tf_static"][0].durability.name == "TRANSIENT_LOCAL" and rb_qos["/map"][0].durability.name ==
      "TRANSIENT_LOCAL", "/tf_static and /map are transient local, as a late RViz needs")
inspected = subprocess.run([mbot_nav, "--config", config / "inspect.ini", "--set", f"source.path={log}",
                            "--set", f"output.dir={work / 'inspect'}", "--set", "pipeline.progress=off"],
                           capture_output=True, text=True)
lidar = json.loads((work / "inspect/inspect.json").read_text())["channels"]["LIDAR"]["count"]
check(rb_counts["/scan"] == lidar, f"every scan of the log recorded ({rb_counts['/scan']} of {lidar})")
tum = [line.split() for line in (bag / "slam.tum").read_text().split("\n") if line and not line.startswith("#")]
poses = {}
with AnyReader([bag]) as reader:
    for c, _t, raw in reader.messages(connections=[x for x in reader.connections if x.topic == "/estimated_pose"]):
        m = reader.deserialize(raw, c.msgtype)
        poses[m.header.stamp.sec * 1_000_000 + m.header.stamp.nanosec // 1000] = m.pose.position
matched = [(poses[round(float(t[0]) * 1e6)], float(t[1]), float(t[2])) for t in tum if round(float(t[0]) * 1e6) in poses]
worst = max((abs(p.x - x) + abs(p.y - y) for p, x, y in matched), default=1.0)
check(len(matched) >= len(tum) - 1 and worst < 1e-5,
      f"/estimated_pose holds slam.tum's poses ({len(matched)} of {len(tum)} matched by stamp, worst {worst:.2e} m)")
grid = rb_last["/map"]
yaml_map = YAML(typ="safe").load((bag / "slam_map.yaml").read_text())
check(abs(grid.info.resolution - yaml_map["resolution"]) < 1e-6 and grid.info.width > 0 and
      set(grid.data.tolist()) <= {-1, 0, 100}, f"/map: {grid.info.width}×{grid.info.height} at "
      f"{grid.info.resolution} m, trinary values")
scan = fox_last["/scan"]
check(len(scan.ranges) > 100 and abs(scan.angle_min + 3.14159) < 1e-3,
      f"/scan decoded by mcap-ros2-support: {len(scan.ranges)} ranges from {scan.angle_min:.4f} rad")

# 2. Interrupted: the simulated Maze Explorer, Ctrl-C after a few seconds.
sim = work / "interrupted"
proc = subprocess.Popen([mbot_nav, "--config", config / "maze_explorer.ini", "--set", f"output.dir={sim}",
                         "--set", "pipeline.progress=off", "--set", "record.format=mcap",
                         "--set", "source.realtime_factor=2"],
                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
time.sleep(4)
proc.send_signal(signal.SIGINT)
out, _ = proc.communicate(timeout=120)
print(out[-800:])
check((sim / "run.mcap").exists() and (sim / "metadata.yaml").exists() and not (sim / "run.mcap.tmp").exists(),
      "the interrupted run left run.mcap and metadata.yaml, no temporary file")
if (sim / "run.mcap").exists():
    _h, s2, c2, _l, _m = open_with_foxglove(sim)
    check(sum(c2.values()) > 0 and s2.statistics.message_count == sum(c2.values()),
          f"the interrupted bag is whole: {sum(c2.values())} messages, CRCs valid")
    # The exploration's own topics, decoded by rosbags' Jazzy types as well.
    r2, last2, _q2 = open_with_rosbags(sim)
    print("topics:", ", ".join(f"{t} {n}" for t, n in sorted(r2.items())))
    check(r2 == c2, "rosbags and Foxglove's reader read the same messages of the exploration")
    for topic, msgtype in (("/frontier_markers", "visualization_msgs/msg/MarkerArray"),
                           ("/mission_state", "std_msgs/msg/String"), ("/planned_path", "nav_msgs/msg/Path"),
                           ("/encoders", "mbot_interfaces/msg/Encoders"),
                           ("/motor_vel", "mbot_interfaces/msg/MotorVelocity")):
        check(r2.get(topic, 0) > 0, f"{topic} recorded ({r2.get(topic, 0)}, {msgtype})")
    if "/frontier_markers" in last2:
        markers = last2["/frontier_markers"].markers
        check(markers and markers[0].action == 3 and all(m.type == 8 and len(m.points) > 0 for m in markers[1:]),
              f"/frontier_markers: a DELETEALL, then POINTS markers ({len(markers) - 1} regions)")
    if "/mission_state" in last2:
        check(last2["/mission_state"].data.split(":")[0] in ("initializing", "exploring", "returning_home"),
              f"/mission_state says {last2['/mission_state'].data!r}")
# 3. Heavy Lift's first 20 s on the simulator: the camera's tags as apriltag_ros publishes them,
#    /detections (apriltag_msgs/AprilTagDetectionArray) and each tag's pose on /tf. rosbags decodes
#    them with the types of apriltag_msgs' own .msg files (Jazzy's 2.0), Foxglove's reader with the
#    schema in the file.
lift = work / "heavy_lift"
p = subprocess.run([mbot_nav, "--config", config / "heavy_lift.ini", "--set", f"output.dir={lift}",
                    "--set", "pipeline.progress=off", "--set", "record.format=mcap", "--set", "source.duration_s=20",
                    "--set", "referee.time_limit_s=20"], capture_output=True, text=True)
print(p.stdout[-400:] + p.stderr[-400:])
check(p.returncode == 0, f"the recorded Heavy Lift run exited 0 ({p.returncode})")
if (lift / "run.mcap").exists():
    _h, _s, c3, fox3, _m = open_with_foxglove(lift)
    ts = get_typestore(Stores.ROS2_JAZZY)
    ts.register(get_types_from_msg("float64 x\nfloat64 y\n", "apriltag_msgs/msg/Point"))
    ts.register(get_types_from_msg("string family\nint32 id\nint32 hamming\nfloat32 goodness\nfloat32 decision_margin\n"
                                   "Point centre\nPoint[4] corners\nfloat64[9] homography\n",
                                   "apriltag_msgs/msg/AprilTagDetection"))
    ts.register(get_types_from_msg("std_msgs/Header header\nAprilTagDetection[] detections\n",
                                   "apriltag_msgs/msg/AprilTagDetectionArray"))
    seen, tag_frames, arrays = [], set(), 0
    with AnyReader([lift], default_typestore=ts) as reader:
        for c, _t, raw in reader.messages(connections=[x for x in reader.connections if x.topic in ("/detections", "/tf")]):
            m = reader.deserialize(raw, c.msgtype)
            if c.topic == "/detections":
                arrays += 1
                seen += list(m.detections)
            else:
                tag_frames |= {t.child_frame_id for t in m.transforms if t.child_frame_id.startswith("tag36h11:")}
    check(arrays > 0 and arrays == c3.get("/detections", 0),
          f"/detections: {arrays} arrays (one per camera frame), as Foxglove's reader counts")
    check(len(seen) > 0 and all(d.family == "tag36h11" for d in seen), f"{len(seen)} tag detections, family tag36h11")
    inside = all(0 <= k.x < 640 and 0 <= k.y < 480 for d in seen for k in d.corners)
    check(seen and inside and all(abs(d.homography[8]) > 0 for d in seen) and all(d.decision_margin > 0 for d in seen),
          "every detection's corners lie in the 640×480 image, with its homography and decision margin")
    ids = sorted({d.id for d in seen})
    check(seen and tag_frames == {f"tag36h11:{i}" for i in ids},
          f"each tag's pose on /tf as apriltag_ros names it ({sorted(tag_frames)})")
    last = fox3.get("/detections")
    check(last is not None and last.header.frame_id == "camera", "mcap-ros2-support decodes /detections (frame camera)")
if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("PASS")
