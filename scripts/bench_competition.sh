#!/usr/bin/env bash
# Runs every competition event on its shipped arena (and the Maze Explorer on every shipped maze)
# over seeds 1..N (default 10) and prints one row per event and arena: the figures in
# BENCHMARKS.md "Competition on the simulator".
#   scripts/bench_competition.sh [N] [out_dir]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-10}
out=${2:-out/bench_competition}
bin=build/apps/mbot_nav/mbot_nav
run() {  # name config extra-sets...
  local name=$1 config=$2; shift 2
  for s in $(seq 1 "$n"); do
    "$bin" --quiet --config "config/$config" --set pipeline.seed="$s" --set output.dir="$out/$name/$s" \
      --set pipeline.progress=off "$@" > /dev/null 2>&1 || true
  done
  python3 - "$out/$name" "$name" "$n" <<'PY'
import json, statistics, sys, os
d, name, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
rows = [json.load(open(os.path.join(d, str(s), 'score.json'))) for s in range(1, n + 1)
        if os.path.exists(os.path.join(d, str(s), 'score.json'))]
med = lambda xs: statistics.median(xs) if xs else float('nan')
done = [r for r in rows if r['completed']]
pts = [r['points']['total'] for r in rows]
times = [r['time_s'] for r in done]
line = '| %s | %d/%d | %g (min %g) of %s | %.1f s [%.1f-%.1f] | %d | ' % (
    name, len(done), n, med(pts), min(pts), rows[0]['points']['max'],
    med(times), min(times), max(times), sum(1 for r in rows if r['collisions'] > 0))
if 'map' in rows[0]:
    line += '%.3f / %.3f m, %.1f deg | %.1f %% (min %.1f %%) | ' % (
        med([r['final_error']['x_m'] for r in done]), med([r['final_error']['y_m'] for r in done]),
        med([r['final_error']['theta_deg'] for r in done]), 100 * med([r['map']['coverage'] for r in rows]),
        100 * min(r['map']['coverage'] for r in rows))
else:
    line += 'SLAM %.3f / %.3f m at the end | level 3 in %d/%d, localized in %.2f s | ' % (
        med([r['slam_final_error']['x_m'] for r in rows]), med([r['slam_final_error']['y_m'] for r in rows]),
        sum(1 for r in rows if r['levels_reached'] == 3), n, med([r['localized_at_s'] for r in rows if r['localized_at_s'] is not None]))
line += '%.0fx |' % med([r['real_time_factor'] for r in rows])
print(line, flush=True)
PY
}
echo "| event / arena | completed | points, median (min) | time, median [range] | runs with a collision | final pose error (median) / warehouse | map coverage (median) / warehouse | RTF (median) |"
echo "|---|---|---|---|---|---|---|---|"
run speed_run speed_run.ini
for m in maze_1 maze_2 maze_3; do run "maze_explorer/$m" maze_explorer.ini --set "source.path=datasets/arenas/$m.arena"; done
run maze_explorer/center_maze maze_explorer.ini --set 'source.path=${datasets}/botlab/mbot_example_logs_maps/center_maze.map' \
  --set 'source.start=-0.9, -0.6, 45'
run warehouse warehouse.ini
