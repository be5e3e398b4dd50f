#!/bin/bash
# The `mazes` label: config/sweep_mazes.ini over generated mazes MBOT_MAZE_FIRST..MBOT_MAZE_LAST
# (default 1-100), seed 1, under GNU parallel on every core, merged (config/merge_sweep.ini); every
# maze must be within every bound (completed, no collision, coverage >= 99 %, walls >= 95 %, home
# within 0.05 m). The table: <out>/sweep.md (BENCHMARKS.md).
#   tests/sweep/maze_sweep.sh <mbot_nav> <source dir> <out dir>
set -uo pipefail
bin=$1 src=$2 out=$3
first=${MBOT_MAZE_FIRST:-1} last=${MBOT_MAZE_LAST:-100}
cd "$src" || exit 1
parallel --version 2> /dev/null | grep -q "GNU parallel" || { echo "FAIL: GNU parallel is not installed"; exit 1; }
rm -rf "$out"
"$bin" --config config/sweep_mazes.ini --set sweep.mazes="$first-$last" --set output.dir="$out" || exit 1
start=$(date +%s.%N)
parallel --retries 3 --joblog "$out/parallel.log" -a "$out/jobs.txt"
status=$?
echo "GNU parallel: $(wc -l < "$out/jobs.txt") jobs in $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s wall (exit $status)"
"$bin" --quiet --config config/merge_sweep.ini --set source.path="$out" --set output.dir="$out.merge" || exit 1
cat "$out/sweep.md"
python3 - "$out/sweep.csv" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ok = [r for r in rows if r['status'] == 'ok']
bad = [r['id'] for r in rows if r['status'] != 'ok' or r['score.completed'] != '1' or r['score.collisions'] != '0']
# The Maze Explorer's bounds: completed, no collision, coverage >= 99 %, walls >= 95 %, home <= 0.05 m.
within = [r for r in ok if r['score.completed'] == '1' and r['score.collisions'] == '0'
          and float(r['score.map.coverage']) >= 0.99 and float(r['score.map.wall_precision']) >= 0.95
          and math.hypot(float(r['score.final_error.x_m']), float(r['score.final_error.y_m'])) <= 0.05]
outside = [r['maze'] for r in rows if r not in within]
print('%d mazes; within every bound: %d (outside: %s)' % (len(rows), len(within), ', '.join(outside) or 'none'))
print('%d mazes; not completed, failed or with a collision: %s' % (len(rows), ', '.join(bad) or 'none'))
sys.exit(1 if bad or outside else 0)
PY
