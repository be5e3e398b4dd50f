#!/usr/bin/env bash
# A replay published over DDS (mbot_nav's `ros2` output) seen by the other DDS vendor, as RViz or
# Foxglove would see it: SLAM replays a real botlab log (config/slam_replay.ini at real time) with
# `[pipeline] outputs = ros2`, while the Fast DDS peer (tests/ros2/fastdds_peer, `listen`) reads
# /scan and /tf for 6 s, then joins late for /map and /tf_static (transient local). Inside a private
# network namespace (loopback up, multicast on it).
#   fastdds_replay.sh <mbot_nav> <mbot_fastdds_peer> <config dir> <output dir>   (MBOT_DATASETS_DIR)
set -u
bin=$1 peer=$2 config=$3 out=$4
netns=$(cd "$(dirname "$0")/../live" && pwd)/in_netns.sh
if [ ! -d "${MBOT_DATASETS_DIR:-}/botlab" ]; then
  echo "no shared datasets at '${MBOT_DATASETS_DIR:-}' (the replay needs a botlab log)"
  if [ "${CI:-}" = true ]; then echo "FAIL: CI needs them"; exit 1; fi
  echo "SKIPPED"; exit 77
fi
rm -rf "$out" && mkdir -p "$out"
export bin peer config out
"$netns" bash -c '
  set -u
  "$bin" --config "$config/slam_replay.ini" --set output.dir="$out/replay" --set pipeline.progress=off \
    --set pipeline.playback_speed=1 --set pipeline.outputs=dds --set dds.type=ros2 > "$out/replay.log" 2>&1 &
  replay=$!
  sleep 1
  "$peer" 0 6 listen > "$out/peer.log" 2>&1
  peer_rc=$?
  kill -INT $replay 2>/dev/null
  wait $replay
  replay_rc=$?
  echo "peer exit $peer_rc, replay exit $replay_rc"
  # Stopped with Ctrl-C: the replay exits 130 and still writes its outputs.
  exit $(( peer_rc != 0 || (replay_rc != 0 && replay_rc != 130) ))
'
rc=$?
[ $rc -eq 77 ] && exit 77  # no network namespace here (in_netns.sh said why)
echo "--- Fast DDS peer"; cat "$out/peer.log"
echo "--- replay"; grep -E "output ros2|interrupted|done|error" "$out/replay.log" | tail -4
[ $rc -eq 0 ] || { echo "FAIL"; exit 1; }
grep -q "output ros2: published .*/scan" "$out/replay.log" || { echo "FAIL: the replay says it published no /scan"; exit 1; }
echo PASS
