#!/usr/bin/env bash
# The viewer's cost to the autonomy loop in instructions (repeatable where timings are not): the
# simulated Maze Explorer (config/maze_explorer.ini, unpaced) under valgrind's callgrind with one
# count per thread, three ways — the viewer off, on with no client, on with 3 clients of Foxglove's
# protocol (tests/viewer/foxglove_client.mjs, every channel). Prints the pipeline thread's
# instructions (the autonomy loop: sources, SLAM, the mission, handing events to outputs) and the
# viewer's threads' (encoding and sending), per run.
#   scripts/bench_viewer_callgrind.sh      (needs valgrind, the build and scripts/install_deps.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind > /dev/null || { echo "valgrind is not installed (apt-get install valgrind)"; exit 1; }
bin=$PWD/build/apps/mbot_nav/mbot_nav
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
one() {  # one <label> <clients> [--set ...]
  local label=$1 clients=$2; shift 2
  local log="$out/$label.log"
  # Paced at 1x (slower than valgrind runs anyway): the clients connect before the run is over.
  valgrind --tool=callgrind --separate-threads=yes --callgrind-out-file="$out/$label.cg" "$bin" \
    --config config/maze_explorer.ini --set output.dir="$out/run_$label" --set pipeline.progress=off \
    --set source.realtime_factor=1 "$@" > "$log" 2>&1 &
  local run=$!
  local pids=()
  if [ "$clients" -gt 0 ]; then
    for _ in $(seq 600); do grep -q "^viewer: Foxglove at" "$log" && break; sleep 0.1; done
    local url
    url=$(sed -n 's/.*Foxglove at \(ws:[^ ,]*\).*/\1/p' "$log" | head -1)
    for c in $(seq "$clients"); do
      (cd tests/viewer && exec node foxglove_client.mjs "$url" 600 "$out/${label}_client$c.json" > /dev/null 2>&1) &
      pids+=($!)
    done
  fi
  wait $run
  [ ${#pids[@]} -eq 0 ] || kill "${pids[@]}" 2> /dev/null || true
  wait || true
  python3 - "$out" "$label" <<'PY'
import glob, re, sys
out, label = sys.argv[1], sys.argv[2]
counts = []
for f in sorted(glob.glob(f"{out}/{label}.cg-*")):
    m = re.search(r"-(\d+)$", f)
    total = 0
    for line in open(f):
        if line.startswith("summary:") or line.startswith("totals:"):
            total = int(line.split()[1]); break
    counts.append((int(m.group(1)), total))
counts.sort()
main = counts[0][1] if counts else 0
rest = ", ".join(f"{c / 1e6:,.1f}" for _, c in counts[1:])
print(f"{label}: pipeline thread {main / 1e6:,.1f} M instructions; the other threads {rest} M")
PY
}
one off 0
one on0 0 --set viewer.enabled=true --set viewer.port=0 --set viewer.http_port=0
one on3 3 --set viewer.enabled=true --set viewer.port=0 --set viewer.http_port=0
