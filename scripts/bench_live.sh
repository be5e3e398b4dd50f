#!/usr/bin/env bash
# The live path's cost, over LCM and over ROS 2 (DDS): the autonomy (live.ini / ros2_live.ini)
# explores maze_1 against the simulated robot (sim_robot.ini / sim_robot_ros2.ini) as two processes
# in a private network namespace, `seconds` of wall clock per run, `runs` runs per case. Cases: each
# transport as shipped (OpenMP threads sleep between scans: the app sets OMP_WAIT_POLICY=PASSIVE
# on a bus) and, as the baseline, with libgomp's default policy (spin after each parallel region;
# OMP_WAIT_POLICY set empty, which libgomp ignores). Prints the medians over the runs: the
# autonomy's CPU seconds (user + system, /usr/bin/time) per wall second, and the robot's loop
# latency (a scan published → the first /cmd_vel received after it: median and p99 of each run).
#   scripts/bench_live.sh [seconds] [runs] [build dir]      (default 60 s, 3 runs, build)
# CASES="lcm ros2_1t …" picks cases; <transport>_1t runs the autonomy on one OpenMP thread
# (OMP_NUM_THREADS=1, no re-exec).
set -eu
seconds=${1:-60}
runs=${2:-3}
build=${3:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$root/$build/apps/mbot_nav/mbot_nav
out=$(mktemp -d /tmp/bench_live.XXXX)
export bin root seconds
for run in $(seq 1 "$runs"); do
  for case in ${CASES:-lcm ros2 lcm_spin ros2_spin}; do
    dir=$out/$case/$run
    mkdir -p "$dir"
    export case dir
    unshare -n bash -c '
      set -eu
      ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo
      case $case in lcm*) a=live.ini r=sim_robot.ini ;; *) a=ros2_live.ini r=sim_robot_ros2.ini ;; esac
      case $case in *_spin) export OMP_WAIT_POLICY= ;; *_1t) export OMP_WAIT_POLICY= OMP_NUM_THREADS=1 ;; *) unset OMP_WAIT_POLICY ;; esac
      /usr/bin/time -f "%U %S %e" -o "$dir/time" "$bin" --config "$root/config/$a" \
        --set output.dir="$dir/autonomy" --set source.duration_s=$seconds --set pipeline.progress=off \
        > "$dir/autonomy.log" 2>&1 &
      sleep 1
      "$bin" --config "$root/config/$r" --set output.dir="$dir/robot" --set pipeline.progress=off \
        --set source.duration_s=$((seconds - 1)) --set referee.time_limit_s=$((seconds - 1)) \
        > "$dir/robot.log" 2>&1 || true
      wait
    ' 2> /dev/null || { echo "bench_live: run $run of $case failed (logs in $dir)"; exit 1; }
  done
done
python3 - "$out" "$runs" "${CASES:-lcm ros2 lcm_spin ros2_spin}" <<'PY'
import json, statistics, sys
from pathlib import Path
out, runs = Path(sys.argv[1]), int(sys.argv[2])
print(f"{'case':<10} {'CPU s/run':>10} {'% of a core':>12} {'latency p50':>12} {'latency p99':>12}   (medians of {runs} runs)")
for case in sys.argv[3].split():
    cpu, share, p50, p99 = [], [], [], []
    for run in range(1, runs + 1):
        d = out / case / str(run)
        user, sys_, wall = map(float, (d / "time").read_text().split())
        cpu.append(user + sys_)
        share.append(100 * (user + sys_) / wall)
        lat = json.loads((d / "robot" / "loop_latency.json").read_text())
        p50.append(lat["median_ms"])
        p99.append(lat["p99_ms"])
    m = statistics.median
    print(f"{case:<10} {m(cpu):10.2f} {m(share):11.1f}% {m(p50):9.2f} ms {m(p99):9.2f} ms")
PY
echo "logs: $out"
