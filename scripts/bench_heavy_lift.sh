#!/usr/bin/env bash
# Heavy Lift on its shipped arena with 1, 2 and 3 crates over seeds 1..N (default 10): one row per
# crate count, the figures in BENCHMARKS.md "Heavy Lift over ten seeds".
#   scripts/bench_heavy_lift.sh [N] [out_dir]
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-10}
out=${2:-out/bench_heavy_lift}
bin=build/apps/mbot_nav/mbot_nav
stacks=("1:11" "1:11, 2:12" "1:11, 2:12, 3:13")
echo "| crates | completed | points, median (min) | time, median [range] | runs with a collision | lifted / stacked (all runs) | RTF (median) |"
echo "|---|---|---|---|---|---|---|"
for c in 1 2 3; do
  for s in $(seq 1 "$n"); do
    "$bin" --quiet --config config/heavy_lift.ini --set pipeline.seed="$s" --set output.dir="$out/$c/$s" \
      --set pipeline.progress=off --set "mission.stack=${stacks[$((c - 1))]}" --set referee.crates="$c" \
      > /dev/null 2>&1 || true
  done
  python3 - "$out/$c" "$c" "$n" <<'PY'
import json, statistics, sys, os
d, c, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = [json.load(open(os.path.join(d, str(s), 'score.json'))) for s in range(1, n + 1)
        if os.path.exists(os.path.join(d, str(s), 'score.json'))]
done = [r for r in rows if r['completed']]
pts = [r['points']['total'] for r in rows]
times = [r['time_s'] for r in done] or [float('nan')]
lifted = sum(k['lifted'] for r in rows for k in r['crates'])
stacked = sum(k['stacked'] for r in rows for k in r['crates'])
print('| %d | %d/%d | %g (min %g) of %d | %.1f s [%.1f-%.1f] | %d | %d / %d of %d | %.1fx |' % (
    c, len(done), n, statistics.median(pts), min(pts), 100 * c, statistics.median(times), min(times), max(times),
    sum(1 for r in rows if r['collisions'] > 0), lifted, stacked, c * n,
    statistics.median([r['real_time_factor'] for r in rows])), flush=True)
PY
done
