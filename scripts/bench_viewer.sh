#!/usr/bin/env bash
# The viewer's cost (BENCHMARKS.md, "Viewer"): the simulated Maze Explorer paced at 4x real time
# (config/maze_explorer.ini), three ways in one run of this script — the viewer off, on with no
# client, on with 3 clients of Foxglove's protocol (tests/viewer/foxglove_client.mjs, every channel)
# — each `runs` times. Prints SLAM's median time per scan (the autonomy loop's main cost), the
# process's CPU seconds, and the bytes per second each client received per channel. Then the
# scan-to-screen lag in headless Chromium (tests/viewer/browser.mjs, 20 s of watching) at real time.
#   scripts/bench_viewer.sh [runs]       (default 3; needs the build and scripts/install_deps.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
bin=build/apps/mbot_nav/mbot_nav
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
one() {  # one <label> <clients> [--set ...]
  local label=$1 clients=$2; shift 2
  local log="$out/$label.log"
  /usr/bin/time -f "%U %S" -o "$out/$label.time" "$bin" --config config/maze_explorer.ini --set source.realtime_factor=4 \
    --set output.dir="$out/run_$label" --set pipeline.progress=off "$@" > "$log" 2>&1 &
  local run=$!
  if [ "$clients" -gt 0 ]; then
    for _ in $(seq 100); do grep -q "^viewer: Foxglove at" "$log" && break; sleep 0.1; done
    local url
    url=$(sed -n 's/.*Foxglove at \(ws:[^ ,]*\).*/\1/p' "$log" | head -1)
    for c in $(seq "$clients"); do
      (cd tests/viewer && node foxglove_client.mjs "$url" 12 "$out/${label}_client$c.json" > /dev/null) &
    done
  fi
  wait $run
  wait
  local ms cpu
  ms=$(sed -n 's/.*median \([0-9.]*\) ms per scan.*/\1/p' "$log")
  cpu=$(awk '{print $1 + $2}' "$out/$label.time")
  echo "$label $ms $cpu"
}
declare -A ms cpu
for r in $(seq "$runs"); do
  for mode in off on0 on3; do
    case $mode in
      off) line=$(one "off_$r" 0) ;;
      on0) line=$(one "on0_$r" 0 --set viewer.enabled=true --set viewer.port=0 --set viewer.http_port=0) ;;
      on3) line=$(one "on3_$r" 3 --set viewer.enabled=true --set viewer.port=0 --set viewer.http_port=0) ;;
    esac
    read -r _ m c <<< "$line"
    ms[$mode]+="$m "
    cpu[$mode]+="$c "
  done
done
median() { tr ' ' '\n' | grep . | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
echo "viewer bench: maze_explorer.ini at 4x real time, $runs runs each (medians)"
for mode in off on0 on3; do
  echo "  $mode: SLAM median $(echo "${ms[$mode]}" | median) ms per scan, process CPU $(echo "${cpu[$mode]}" | median) s"
done
python3 - "$out" <<'PY'
import glob, json, sys
reports = [json.load(open(f)) for f in sorted(glob.glob(sys.argv[1] + "/on3_*_client*.json"))]
topics = sorted({t for r in reports for t in r["bytes"]})
print("  bytes per second per client (12 s window, median over %d clients):" % len(reports))
for t in topics:
    v = sorted(r["bytes"].get(t, 0) / 12.0 for r in reports)
    print("    %-13s %8.0f B/s" % (t, v[len(v) // 2]))
PY

# Scan to screen: the page in headless Chromium, the Maze Explorer at real time (a robot's rate).
for r in $(seq "$runs"); do
  log="$out/lag_$r.log"
  "$bin" --config config/maze_explorer.ini --set source.realtime_factor=1 --set source.duration_s=40 \
    --set output.dir="$out/run_lag_$r" --set pipeline.progress=off --set viewer.enabled=true --set viewer.port=0 \
    --set viewer.http_port=0 > "$log" 2>&1 &
  run=$!
  for _ in $(seq 100); do grep -q "^viewer: Foxglove at" "$log" && break; sleep 0.1; done
  page=$(sed -n 's/.*the page at \(http:[^ ,]*\).*/\1/p' "$log" | head -1)
  (cd tests/viewer && HOLD_S=20 node browser.mjs "$page" "$out/lag_$r.png" "$out/lag_$r.json" | grep "scan to screen") || true
  kill $run 2> /dev/null || true
  wait $run 2> /dev/null || true
done
