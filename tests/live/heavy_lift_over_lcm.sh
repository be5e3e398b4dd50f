#!/usr/bin/env bash
# Heavy Lift over LCM, three processes as on a real MBot: the simulated robot with its forklift and
# camera (config/sim_robot_heavy_lift.ini: frames out on CAMERA, MBOT_FORKLIFT_CMD in,
# MBOT_FORKLIFT_STATUS out), the vision process (config/vision_heavy_lift.ini: CAMERA in,
# MBOT_APRILTAG_ARRAY out) and the autonomy (config/live_heavy_lift.ini: SLAM and the heavy_lift
# mission), over udpm inside a private network namespace, in real time. One crate by default.
# Asserts the robot's referee saw every crate lifted and stacked, the mission complete and no
# collision, and that no process rejected a message. Exits 77 (skipped) where namespaces are not
# permitted.
#   heavy_lift_over_lcm.sh <mbot_nav> <config dir> <output dir> [crates] [seed]
set -u
bin=$1 config=$2 out=$3 crates=${4:-1} seed=${5:-1}
if ! unshare -n true 2>/dev/null; then
  echo "SKIPPED: cannot create a network namespace here (unshare -n not permitted); the live test needs one"
  exit 77
fi
command -v ip > /dev/null || { echo "SKIPPED: ip is not installed; scripts/install_deps.sh installs it"; exit 77; }
stacks=("1:11" "1:11, 2:12" "1:11, 2:12, 3:13")
stack=${stacks[$((crates - 1))]}
rm -rf "$out" && mkdir -p "$out"
export bin config out crates seed stack
unshare -n bash -c '
  set -u
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "cannot set up loopback multicast"; exit 1; }
  "$bin" --config "$config/live_heavy_lift.ini" --set output.dir="$out/autonomy" --set source.end_after_silence_s=5 \
    --set pipeline.seed=$seed --set "mission.stack=$stack" --set pipeline.progress=off > "$out/autonomy.log" 2>&1 &
  autonomy=$!
  "$bin" --config "$config/vision_heavy_lift.ini" --set output.dir="$out/vision" --set source.end_after_silence_s=5 \
    --set pipeline.progress=off > "$out/vision.log" 2>&1 &
  vision=$!
  sleep 1  # both listen before the robot starts publishing
  "$bin" --config "$config/sim_robot_heavy_lift.ini" --set output.dir="$out/robot" --set pipeline.progress=off \
    --set pipeline.seed=$seed --set referee.crates=$crates --set referee.time_limit_s=240 --set source.duration_s=260 \
    > "$out/robot.log" 2>&1
  robot_rc=$?
  wait $autonomy
  autonomy_rc=$?
  wait $vision
  vision_rc=$?
  echo "robot exit $robot_rc, vision exit $vision_rc, autonomy exit $autonomy_rc"
  exit $(( robot_rc != 0 || autonomy_rc != 0 || vision_rc != 0 ))
'
rc=$?
echo "--- robot (simulator + referee)"; tail -8 "$out/robot.log"
echo "--- vision"; grep -E "lcm|tag_sightings|error" "$out/vision.log" | tail -4
echo "--- autonomy"; grep -E "lcm|mission: (lifting|setting_down|completed|failed)|error" "$out/autonomy.log" | tail -8
[ $rc -eq 0 ] || { echo "FAIL: a process failed"; exit 1; }
score="$out/robot/score.json"
[ -f "$score" ] || { echo "FAIL: no score.json from the robot's referee"; exit 1; }
fail=0
grep -q '"completed": true' "$score" || { echo "FAIL: the referee did not see the mission complete"; fail=1; }
grep -q '"collisions": 0,' "$score" || { echo "FAIL: the robot hit something"; fail=1; }
points=$(python3 -c 'import json, sys; p = json.load(open(sys.argv[1]))["points"]; print(p["total"], p["max"])' "$score")
[ "$points" = "$((100 * crates)) $((100 * crates))" ] ||
  { echo "FAIL: not every crate lifted and stacked: points (total, max) $points"; fail=1; }
grep -q '"state": "completed"' "$out/autonomy/mission.json" || { echo "FAIL: the autonomy's mission did not complete"; fail=1; }
for p in autonomy vision; do
  grep -E "^lcm: [0-9.]+ messages/s" "$out/$p.log" | tail -1 | grep -q " 0 rejected" ||
    { echo "FAIL: the $p process rejected messages"; fail=1; }
done
[ $fail -eq 0 ] && echo "PASS: $crates crate(s) lifted and stacked over LCM by three processes, no collision"
exit $fail
