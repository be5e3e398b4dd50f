#!/usr/bin/env bash
# The autonomy (config/live.ini) explores maze_1 through the simulated robot (config/sim_robot.ini),
# two processes talking real LCM (udpm multicast), inside a private network namespace so no packet
# leaves the test: loopback up, a multicast route on lo. Asserts the exploration completed (the
# robot's referee saw EXPLORATION_STATUS completed), the map was published and scored, and no
# collision happened; lcm-logger records the bus, and the log replays (config/live_replay.ini) to the
# live run's map. Where namespaces are not permitted it says so and exits 77 (skipped).
#   explore_over_lcm.sh <mbot_nav> <mbot_live_tests> <config dir> <output dir>
set -u
bin=$1 live_tests=$2 config=$3 out=$4
if ! unshare -n true 2>/dev/null; then
  echo "SKIPPED: cannot create a network namespace here (unshare -n not permitted); the live test needs one"
  exit 77
fi
for tool in ip lcm-logger; do
  command -v $tool > /dev/null || { echo "SKIPPED: $tool is not installed; scripts/install_deps.sh installs it"; exit 77; }
done
rm -rf "$out" && mkdir -p "$out"
export bin config out
unshare -n bash -c '
  set -u
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "cannot set up loopback multicast"; exit 1; }
  lcm-logger --quiet --lcm-url="udpm://239.255.76.67:7667?ttl=0" "$out/run.log" > "$out/logger.log" 2>&1 &
  logger=$!
  trap "kill $logger 2>/dev/null" EXIT
  "$bin" --config "$config/live.ini" --set output.dir="$out/autonomy" --set source.end_after_silence_s=3 \
    --set pipeline.progress=off > "$out/autonomy.log" 2>&1 &
  autonomy=$!
  sleep 1  # the autonomy listens before the robot starts publishing
  # Time limits below ctest'"'"'s 300 s, so a stalled run fails with its logs instead of timing out.
  "$bin" --config "$config/sim_robot.ini" --set output.dir="$out/robot" --set pipeline.progress=off \
    --set referee.time_limit_s=150 --set source.duration_s=180 > "$out/robot.log" 2>&1
  robot_rc=$?
  wait $autonomy
  autonomy_rc=$?
  kill -INT $logger; wait $logger
  echo "robot exit $robot_rc, autonomy exit $autonomy_rc"
  exit $(( robot_rc != 0 || autonomy_rc != 0 ))
'
rc=$?
echo "--- robot (simulator + referee)"; tail -12 "$out/robot.log"
echo "--- autonomy"; grep -E "lcm|mission: (completed|failed)|error" "$out/autonomy.log" | tail -8
[ $rc -eq 0 ] || { echo "FAIL: a process failed"; exit 1; }
score="$out/robot/score.json"
[ -f "$score" ] || { echo "FAIL: no score.json from the robot's referee"; exit 1; }
fail=0
grep -q '"completed": true' "$score" || { echo "FAIL: the referee did not see EXPLORATION_STATUS completed"; fail=1; }
grep -q '"collisions": 0,' "$score" || { echo "FAIL: the robot touched a wall"; fail=1; }
coverage=$(sed -n 's/.*"coverage": \([0-9.]*\).*/\1/p' "$score")
awk -v c="$coverage" 'BEGIN { exit !(c >= 0.99) }' || { echo "FAIL: map coverage $coverage < 0.99 (was SLAM_MAP published?)"; fail=1; }
[ -s "$out/autonomy/slam_map.map" ] || { echo "FAIL: the autonomy wrote no map"; fail=1; }
grep -q '"state": "completed"' "$out/autonomy/mission.json" || { echo "FAIL: the autonomy's mission did not complete"; fail=1; }
# The run lcm-logger recorded replays through the replay pipeline to the same map.
"$bin" --config "$config/live_replay.ini" --set source.path="$out/run.log" --set output.dir="$out/replay" \
  --set pipeline.progress=off > "$out/replay.log" 2>&1 || { echo "FAIL: the recorded run did not replay"; fail=1; }
MBOT_LIVE_MAP="$out/autonomy/slam_map.map" MBOT_REPLAY_MAP="$out/replay/slam_map.map" \
  "$live_tests" --gtest_filter='LiveReplay.*' > "$out/replay_check.log" 2>&1
cat "$out/replay_check.log" | grep -E "agreement|Failure|Expected|Which|actual"
grep -q '\[  PASSED  \] 1 test' "$out/replay_check.log" || { echo "FAIL: the replayed map differs from the live one"; fail=1; }
# The autonomy's last report: nothing of the robot's was rejected.
grep -E "^lcm: [0-9.]+ messages/s" "$out/autonomy.log" | tail -1 | grep -q " 0 rejected" ||
  { echo "FAIL: the autonomy rejected messages from the simulated robot"; fail=1; }
[ $fail -eq 0 ] && echo "PASS: explored over LCM, coverage $coverage, no collision; the recorded run replays to the same map"
exit $fail
