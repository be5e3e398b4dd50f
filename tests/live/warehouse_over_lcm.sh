#!/usr/bin/env bash
# The Warehouse over LCM: the autonomy (config/live_warehouse.ini: global localization in the given
# map, the day's targets and drop-offs from its own keys) drives the simulated robot
# (config/sim_robot_warehouse.ini, a seeded random start) as another process, over udpm inside a
# private network namespace. Real time, so the run makes the first `deliveries` deliveries (default
# 1). Asserts the robot's referee saw the mission complete with every delivery made and no
# collision, and the autonomy rejected nothing. Exits 77 (skipped) where namespaces are not
# permitted.
#   warehouse_over_lcm.sh <mbot_nav> <config dir> <output dir> [deliveries] [seed]
set -u
bin=$1 config=$2 out=$3 deliveries=${4:-1} seed=${5:-2}
if ! unshare -n true 2>/dev/null; then
  echo "SKIPPED: cannot create a network namespace here (unshare -n not permitted); the live test needs one"
  exit 77
fi
command -v ip > /dev/null || { echo "SKIPPED: ip is not installed; scripts/install_deps.sh installs it"; exit 77; }
rm -rf "$out" && mkdir -p "$out"
export bin config out deliveries seed
unshare -n bash -c '
  set -u
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "cannot set up loopback multicast"; exit 1; }
  "$bin" --config "$config/live_warehouse.ini" --set output.dir="$out/autonomy" --set source.end_after_silence_s=5 \
    --set pipeline.seed=$seed --set mission.deliveries=$deliveries --set pipeline.progress=off > "$out/autonomy.log" 2>&1 &
  autonomy=$!
  sleep 1  # the autonomy listens before the robot starts publishing
  "$bin" --config "$config/sim_robot_warehouse.ini" --set output.dir="$out/robot" --set pipeline.progress=off \
    --set pipeline.seed=$seed --set referee.time_limit_s=200 --set source.duration_s=230 > "$out/robot.log" 2>&1
  robot_rc=$?
  wait $autonomy
  autonomy_rc=$?
  echo "robot exit $robot_rc, autonomy exit $autonomy_rc"
  exit $(( robot_rc != 0 || autonomy_rc != 0 ))
'
rc=$?
echo "--- robot (simulator + referee)"; tail -12 "$out/robot.log"
echo "--- autonomy"; grep -E "lcm|mission: (lifting|setting_down|completed|failed)|slam|error" "$out/autonomy.log" | tail -10
[ $rc -eq 0 ] || { echo "FAIL: a process failed"; exit 1; }
score="$out/robot/score.json"
[ -f "$score" ] || { echo "FAIL: no score.json from the robot's referee"; exit 1; }
fail=0
grep -q '"completed": true' "$score" || { echo "FAIL: the referee did not see the mission complete"; fail=1; }
grep -q '"collisions": 0,' "$score" || { echo "FAIL: the robot touched a wall"; fail=1; }
done_stops=$(grep -c '"done_at_s": [0-9]' "$score")
[ "$done_stops" -ge $((2 * deliveries)) ] || { echo "FAIL: the referee judged $done_stops stops done, not $((2 * deliveries))"; fail=1; }
grep -q '"state": "completed"' "$out/autonomy/mission.json" || { echo "FAIL: the autonomy's mission did not complete"; fail=1; }
grep -E "^lcm: [0-9.]+ messages/s" "$out/autonomy.log" | tail -1 | grep -q " 0 rejected" ||
  { echo "FAIL: the autonomy rejected messages from the simulated robot"; fail=1; }
[ $fail -eq 0 ] && echo "PASS: $deliveries deliveries over LCM ($done_stops stops judged done by the referee), no collision"
exit $fail
