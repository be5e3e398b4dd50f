#!/usr/bin/env bash
# The autonomy and the simulated robot as two processes talking ROS 2 over DDS (Cyclone DDS on both
# sides, the MBot's topics, frames and QoS), inside a private network namespace (loopback up,
# multicast on it) so no packet leaves the test. `explore`: config/ros2_live.ini explores maze_1
# through config/sim_robot_ros2.ini; `warehouse`: config/ros2_live_warehouse.ini makes one delivery
# through config/sim_robot_ros2_warehouse.ini. Asserts the robot's referee saw the mission complete
# with no collision (explore: coverage ≥ 99 %), the autonomy's mission completed and it rejected
# nothing. `explore` runs with the viewer on (viewer.enabled beside ros2_live.ini): while the robot
# explores, Foxglove's protocol client subscribes to every channel and validates each message
# against Foxglove's schemas, and headless Chromium opens the page and must see the map, the robot
# and the lidar drawn. Exits 77 (skipped) where namespaces are not permitted.
#   over_ros2.sh <mbot_nav> <config dir> <output dir> explore|warehouse [seed]
set -u
bin=$1 config=$2 out=$3 task=$4 seed=${5:-2}
viewer_dir=$(cd "$(dirname "$0")/../viewer" && pwd)
case $task in
  explore) autonomy_ini=ros2_live.ini robot_ini=sim_robot_ros2.ini limit=150
    extra="--set viewer.enabled=true --set viewer.port=0 --set viewer.http_port=0"
    command -v node > /dev/null && [ -d "$viewer_dir/node_modules/@foxglove/ws-protocol" ] &&
      [ -x "${CHROMIUM:-/usr/bin/chromium}" ] ||
      { echo "FAIL: node, chromium or $viewer_dir/node_modules is missing: run scripts/install_deps.sh"; exit 1; } ;;
  warehouse) autonomy_ini=ros2_live_warehouse.ini robot_ini=sim_robot_ros2_warehouse.ini
    extra="--set mission.deliveries=1" limit=200 ;;
  *) echo "over_ros2.sh: task is explore or warehouse, not '$task'"; exit 2 ;;
esac
rm -rf "$out" && mkdir -p "$out"
export bin config out seed autonomy_ini robot_ini extra limit task viewer_dir
"$(dirname "$0")/in_netns.sh" bash -c '
  set -u
  "$bin" --config "$config/$autonomy_ini" --set output.dir="$out/autonomy" --set source.end_after_silence_s=5 \
    --set pipeline.seed=$seed $extra --set pipeline.progress=off > "$out/autonomy.log" 2>&1 &
  autonomy=$!
  sleep 1  # the autonomy listens before the robot starts publishing
  # Time limits below ctest'"'"'s 300 s, so a stalled run fails with its logs instead of timing out.
  "$bin" --config "$config/$robot_ini" --set output.dir="$out/robot" --set pipeline.progress=off \
    --set pipeline.seed=$seed --set referee.time_limit_s=$limit --set source.duration_s=$((limit + 30)) \
    > "$out/robot.log" 2>&1 &
  robot=$!
  viewer_rc=0
  if [ "$task" = explore ]; then
    for _ in $(seq 100); do grep -q "^viewer: Foxglove at" "$out/autonomy.log" && break; sleep 0.1; done
    line=$(grep -m1 "^viewer: Foxglove at" "$out/autonomy.log")
    [ -n "$line" ] || { echo "FAIL: the autonomy'"'"'s viewer did not start" > "$out/viewer_clients.log"; viewer_rc=1; }
    ws_url=$(echo "$line" | sed -n "s/.*Foxglove at \(ws:[^ ,]*\).*/\1/p")
    page_url=$(echo "$line" | sed -n "s/.*the page at \(http:[^ ,]*\).*/\1/p")
    echo "$line"
    if [ $viewer_rc -eq 0 ]; then
      sleep 8  # the robot is mapping
      (cd "$viewer_dir" && node foxglove_client.mjs "$ws_url" 4 "$out/foxglove_client.json" /map /scan /tf /pose \
        /odom /scene /mission) > "$out/viewer_clients.log" 2>&1 || viewer_rc=1
      (cd "$viewer_dir" && node browser.mjs "$page_url" "$out/page.png" "$out/browser.json" live) \
        >> "$out/viewer_clients.log" 2>&1 || viewer_rc=1
    fi
  fi
  wait $robot
  robot_rc=$?
  wait $autonomy
  autonomy_rc=$?
  echo "robot exit $robot_rc, autonomy exit $autonomy_rc, viewer clients exit $viewer_rc"
  exit $(( robot_rc != 0 || autonomy_rc != 0 || viewer_rc != 0 ))
'
rc=$?
[ $rc -eq 77 ] && exit 77  # no network namespace here (in_netns.sh said why)
echo "--- robot (simulator + referee)"; tail -12 "$out/robot.log"
echo "--- autonomy"; grep -E "ros2|viewer|mission: (lifting|setting_down|completed|failed)|error" "$out/autonomy.log" | tail -10
[ -f "$out/viewer_clients.log" ] && { echo "--- Foxglove's client and Chromium"; tail -15 "$out/viewer_clients.log"; }
[ $rc -eq 0 ] || { echo "FAIL: a process failed"; exit 1; }
score="$out/robot/score.json"
[ -f "$score" ] || { echo "FAIL: no score.json from the robot's referee"; exit 1; }
fail=0
grep -q '"completed": true' "$score" || { echo "FAIL: the referee did not see the mission complete"; fail=1; }
grep -q '"collisions": 0,' "$score" || { echo "FAIL: the robot touched a wall"; fail=1; }
if [ "$task" = explore ]; then
  coverage=$(sed -n 's/.*"coverage": \([0-9.]*\).*/\1/p' "$score")
  awk -v c="$coverage" 'BEGIN { exit !(c >= 0.99) }' || { echo "FAIL: map coverage $coverage < 0.99 (was /map published?)"; fail=1; }
else
  stops=$(grep -c '"done_at_s": [0-9]' "$score")
  [ "$stops" -ge 2 ] || { echo "FAIL: the referee judged $stops stops done, not 2"; fail=1; }
fi
grep -q '"state": "completed"' "$out/autonomy/mission.json" || { echo "FAIL: the autonomy's mission did not complete"; fail=1; }
grep -E "^ros2: [0-9.]+ messages/s" "$out/autonomy.log" | tail -1 | grep -q " 0 rejected" ||
  { echo "FAIL: the autonomy rejected messages from the simulated robot"; fail=1; }
# /reset_odometry: the autonomy called it at start, the simulated robot served it and answered.
grep -q "^ros2: /reset_odometry: Odometry reset to (0, 0, 0)" "$out/autonomy.log" &&
  grep -q "^ros2_bridge: /reset_odometry: odometry reset" "$out/robot.log" ||
  { echo "FAIL: /reset_odometry was not called and answered"; fail=1; }
[ $fail -eq 0 ] && echo "PASS: $task over ROS 2 (DDS), no collision"
exit $fail
