#!/usr/bin/env bash
# The one-hour soak (config/soak.ini: an hour of simulated time in one process — exploration with
# full SLAM, then Warehouse rounds on the map it made), then its
# curves from slam_scans.csv: per 5 simulated minutes, the median and 95th-percentile time per scan
# and the resident memory. Fails when memory grows by more than 16 MB from the first 5 minutes to
# the last: a buffer that grows with every scan fails (the 9.6 KB a scan the consistency metric
# once kept: 276 MB an hour; the per-scan records, before they were streamed to disk: 6.5 MB an
# hour). Time per scan is reported, not asserted (the machines are shared).
#   scripts/soak.sh [output dir] [extra mbot_nav arguments]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/soak}
shift || true
bin=${MBOT_NAV:-build/apps/mbot_nav/mbot_nav}
[ -x "$bin" ] || { echo "soak.sh: $bin is not built (scripts/build.sh)" >&2; exit 1; }
"$bin" --config config/soak.ini --set output.dir="$out" "$@" > "$out.log" 2>&1 ||
  { tail -20 "$out.log"; echo "soak.sh: the run failed" >&2; exit 1; }
grep -E "^done:|slam: [0-9]+ scans" "$out.log"
rounds=$(sed -n 's/.*"rounds": \([0-9]*\).*/\1/p' "$out/mission.json")
echo "warehouse rounds after exploring: $rounds"
grep -q "mission: initializing (explored; now the warehouse)" "$out.log" ||
  { echo "soak.sh: FAIL: the exploration did not complete" >&2; exit 1; }
[ "${rounds:-0}" -ge 2 ] || { echo "soak.sh: FAIL: fewer than two Warehouse rounds in the hour" >&2; exit 1; }
awk -F, 'NR > 1 {
    bin = int($1 / 300); if (bin > 0 && $1 == bin * 300) bin--  # 3600.0 s is the last of the hour
    n[bin]++; v[bin, n[bin]] = $14; if ($15 > 0) rss[bin] = $15; if (bin > last) last = bin
  }
  END {
    print "sim_min  scans  median_ms  p95_ms  rss_mb"
    for (b = 0; b <= last; b++) {
      m = n[b]
      for (i = 1; i <= m; i++) {  # insertion sort (mawk has no asort); a bin holds ~2,400 scans
        x = v[b, i]; j = i - 1
        while (j > 0 && s[j] > x) { s[j + 1] = s[j]; j-- }
        s[j + 1] = x
      }
      printf "%7d  %5d  %9.3f  %6.3f  %6.1f\n", (b + 1) * 5, m, s[int((m + 1) / 2)], s[int(m * 0.95)], rss[b]
    }
    growth = rss[last] - rss[0]
    printf "memory growth from the first 5 minutes to the last: %.1f MB\n", growth
    if (growth > 16) { print "FAIL: memory is not flat"; exit 1 }
  }' "$out/slam_scans.csv" | tee "$out/soak_curves.txt"
