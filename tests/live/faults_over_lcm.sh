#!/usr/bin/env bash
# Faults on the live bus: the simulated robot (config/sim_robot.ini) on one LCM group, the autonomy
# (config/live.ini) on another, and the fault relay (config/fault_relay.ini) between them, inside a
# private network namespace (loopback multicast only). One scenario a run:
#   drops_jitter      10 % of every message lost and 0–50 ms jitter on every channel, both ways:
#                     the exploration still completes, no collision.
#   mixed             5 % drops, 5 % duplicates, 5 % reordered, 2 % with corrupted bytes, 20 ms delay
#                     + 0–20 ms jitter, both ways: corrupt messages are rejected, the rest completes.
#   lidar_silence     LIDAR silent for 3 s mid-run: the autonomy halts the robot (its watchdog), then
#                     resumes when scans return, and completes.
#   robot_restart     the robot process killed mid-run and started again where it stood (odometry
#                     back at zero): the autonomy sees the jump, re-anchors, completes, no collision.
#   autonomy_restart  the autonomy killed (SIGKILL) mid-run and started again from its SLAM
#                     checkpoint (slam.checkpoint_every_s): it resumes on its saved map, completes.
# Where namespaces are not permitted it says so and exits 77 (skipped).
#   faults_over_lcm.sh <mbot_nav> <config dir> <output dir> <scenario>
set -u
bin=$1 config=$2 out=$3 scenario=$4
case $scenario in drops_jitter | mixed | lidar_silence | robot_restart | autonomy_restart) ;;
  *) echo "unknown scenario '$scenario'"; exit 2 ;;
esac
if ! unshare -n true 2>/dev/null; then
  echo "SKIPPED: cannot create a network namespace here (unshare -n not permitted); the live test needs one"
  exit 77
fi
command -v ip > /dev/null || { echo "SKIPPED: ip is not installed; scripts/install_deps.sh installs it"; exit 77; }
rm -rf "$out" && mkdir -p "$out"
export bin config out scenario
unshare -n bash -c '
  set -u
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "cannot set up loopback multicast"; exit 1; }
  robot_url="udpm://239.255.76.67:7667?ttl=0"
  autonomy_url="udpm://239.255.76.68:7668?ttl=0"
  relay_args=()
  case $scenario in
    drops_jitter) relay_args=(--set source.drop_rate=0.1 --set source.jitter_ms=50) ;;
    mixed) relay_args=(--set source.drop_rate=0.05 --set source.duplicate_rate=0.05 --set source.reorder_rate=0.05
                       --set source.corrupt_rate=0.02 --set source.delay_ms=20 --set source.jitter_ms=20) ;;
    lidar_silence) relay_args=(--set source.silences=LIDAR@20+3) ;;
  esac
  "$bin" --config "$config/fault_relay.ini" --set output.dir="$out/relay" --set source.url="$robot_url" \
    --set source.relay_url="$autonomy_url" "${relay_args[@]}" > "$out/relay.log" 2>&1 &
  relay=$!
  # Each runs in the background (a subshell that becomes mbot_nav), so its PID is the process to kill.
  autonomy() {  # $1: output folder, then extra --set arguments
    local dir=$1; shift
    exec "$bin" --config "$config/live.ini" --set source.url="$autonomy_url" --set output.dir="$dir" \
      --set source.end_after_silence_s=3 --set pipeline.progress=off --set slam.checkpoint_every_s=2 "$@" \
      > "$dir.log" 2>&1
  }
  robot() {  # $1: output folder, then extra --set arguments
    local dir=$1; shift
    exec "$bin" --config "$config/sim_robot.ini" --set bridge.url="$robot_url" --set output.dir="$dir" \
      --set pipeline.progress=off --set referee.time_limit_s=150 --set source.duration_s=180 "$@" > "$dir.log" 2>&1
  }
  autonomy "$out/autonomy" &
  autonomy_pid=$!
  sleep 1  # the autonomy listens before the robot starts publishing
  rc=0
  case $scenario in
    robot_restart)
      robot "$out/robot" &
      robot_pid=$!
      sleep 25
      kill -INT $robot_pid; wait $robot_pid
      # The robot stands where it was; its odometry starts again from zero in the new process.
      pose=$(tail -1 "$out/robot/true_path.tum" | awk "{ printf \"%.4f, %.4f, %.3f\", \$2, \$3, 2 * atan2(\$7, \$8) * 180 / 3.14159265358979 }")
      echo "robot restarted at $pose" > "$out/restart.txt"
      robot "$out/robot2" --set "source.start=$pose" &
      wait $! || rc=1
      wait $autonomy_pid || rc=1 ;;
    autonomy_restart)
      robot "$out/robot" &
      robot_pid=$!
      sleep 30
      kill -KILL $autonomy_pid; wait $autonomy_pid 2>/dev/null
      cp "$out/autonomy/slam_checkpoint.ini" "$out/checkpoint_used.ini"
      autonomy "$out/autonomy2" --set slam.resume_from="$out/autonomy/slam_checkpoint.ini" --set mission.home=0,0,0 \
        --set slam.initial_sigma_xy_m=0.05 --set slam.initial_sigma_theta_rad=0.05 &
      autonomy_pid=$!
      wait $robot_pid || rc=1
      wait $autonomy_pid || rc=1 ;;
    *)
      robot "$out/robot" &
      wait $! || rc=1
      wait $autonomy_pid || rc=1 ;;
  esac
  kill -INT $relay; wait $relay
  exit $rc
'
rc=$?
echo "--- relay"; grep -E "relay (LIDAR|MBOT_ODOMETRY|MBOT_VEL_CMD)" "$out/relay.log" | head -3
for r in robot robot2; do [ -f "$out/$r.log" ] && { echo "--- $r"; tail -6 "$out/$r.log"; }; done
final=autonomy
[ $scenario = autonomy_restart ] && final=autonomy2
echo "--- $final"; grep -E "lcm: no|sensors back|odometry jumped|resuming|mission: (completed|failed)|error" "$out/$final.log" | tail -8
# expect FILE PATTERN WHY: FAIL with WHY unless FILE has a line matching the extended regex.
expect() { grep -qE -- "$2" "$1" 2>/dev/null || { echo "FAIL: $3"; fail=1; }; }
fail=0
[ $rc -eq 0 ] || { echo "FAIL: a process failed"; fail=1; }
for s in "$out"/robot*/score.json; do
  [ -f "$s" ] || { echo "FAIL: no score.json from the robot's referee"; fail=1; continue; }
  grep -q '"collisions": 0,' "$s" || { echo "FAIL: the robot touched a wall ($s)"; fail=1; }
done
expect "$out/$final/mission.json" '"state": "completed"' "the autonomy's mission did not complete"
# The robot's referee saw the exploration completed (a restarted robot's referee saw only part).
[ $scenario = robot_restart ] ||
  expect "$out/robot/score.json" '"completed": true' "the referee did not see the exploration completed"
case $scenario in
  drops_jitter) expect "$out/relay.log" "relay LIDAR: [0-9]+ received, [0-9]+ relayed, [1-9][0-9]* dropped" \
    "the relay dropped nothing" ;;
  mixed) expect "$out/relay.log" "relay LIDAR: .* [1-9][0-9]* corrupted" "the relay corrupted nothing" ;;
  lidar_silence)
    expect "$out/autonomy.log" "lcm: no LIDAR" "the silence was not noticed"
    expect "$out/autonomy.log" "lcm: sensors back" "the autonomy did not resume" ;;
  robot_restart)
    expect "$out/autonomy.log" "odometry jumped" "the odometry restart was not detected"
    expect "$out/autonomy/mission.json" '"odometry_restarts": [1-9]' "the mission did not re-anchor its odometry" ;;
  autonomy_restart) expect "$out/autonomy2.log" "slam: resuming from checkpoint" "the autonomy did not resume" ;;
esac
[ $fail -eq 0 ] && echo "PASS: $scenario"
exit $fail
