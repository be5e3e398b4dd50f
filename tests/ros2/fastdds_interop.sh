#!/usr/bin/env bash
# Cross-vendor ROS 2: mbot_nav's autonomy (config/ros2_live.ini, Cyclone DDS) against a robot played
# by Fast DDS (tests/ros2/fastdds_peer: fastddsgen's types from IDL written from the public .msg
# files), inside a private network namespace (loopback up, multicast on it) so no packet leaves the
# test. The peer publishes /tf_static, /odom and /scan for 8 s and asserts that a non-zero /cmd_vel
# comes back, that a late-joining reader gets /map with the room where the mount puts it, and that
# the autonomy announced its node /mbot_nav on ros_discovery_info with /cmd_vel's writer in it; it serves
# /reset_odometry as the MBot's micro-ROS agent does, and the autonomy must take its reply.
#   fastdds_interop.sh <mbot_nav> <mbot_fastdds_peer> <config dir> <output dir>
set -u
bin=$1 peer=$2 config=$3 out=$4
netns=$(cd "$(dirname "$0")/../live" && pwd)/in_netns.sh
rm -rf "$out" && mkdir -p "$out"
export bin peer config out
"$netns" bash -c '
  set -u
  "$bin" --config "$config/ros2_live.ini" --set output.dir="$out/autonomy" --set source.end_after_silence_s=3 \
    --set source.duration_s=60 --set pipeline.progress=off > "$out/autonomy.log" 2>&1 &
  autonomy=$!
  sleep 1  # the autonomy listens before the robot starts
  "$peer" 0 8 > "$out/peer.log" 2>&1
  peer_rc=$?
  wait $autonomy
  autonomy_rc=$?
  echo "peer exit $peer_rc, autonomy exit $autonomy_rc"
  exit $(( peer_rc != 0 || autonomy_rc != 0 ))
'
rc=$?
[ $rc -eq 77 ] && exit 77  # no network namespace here (in_netns.sh said why)
echo "--- Fast DDS peer"; cat "$out/peer.log"
echo "--- autonomy"; grep -E "ros2|error" "$out/autonomy.log" | tail -6
[ $rc -eq 0 ] || { echo "FAIL"; exit 1; }
grep -q "0 rejected" "$out/autonomy.log" || { echo "FAIL: the autonomy rejected messages of the Fast DDS peer"; exit 1; }
grep -q "ros2: /reset_odometry: Odometry reset to (0, 0, 0)" "$out/autonomy.log" ||
  { echo "FAIL: the autonomy did not take the peer's /reset_odometry reply"; exit 1; }
echo PASS
