#!/usr/bin/env bash
# A* against Warthog's A* on Moving AI maps: the same scenario files through Warthog's own program
# (`warthog --alg astar`, its per-query `nanos`: the search only) and through ours (config/movingai.ini
# with search = astar: the stage's per-query time_us, the search only), one after the other on one
# core; prints mean time per query and the ratio per map (BENCHMARKS.md, "A* against Warthog").
# Warthog is not a Debian package: build warthog-core (github.com/ShortestPathLab/warthog-core) with
# CMake -DCMAKE_BUILD_TYPE=Release (-O3) and pass its `warthog` binary.
#   scripts/bench_warthog.sh <warthog binary> [out_dir] [map …]   (maps as dao/den520d, default six)
set -euo pipefail
cd "$(dirname "$0")/.."
warthog=$1
out=${2:-out/bench_warthog}
shift $(( $# >= 2 ? 2 : 1 ))
maps=("$@")
[ ${#maps[@]} -gt 0 ] || maps=(dao/den520d dao/brc202d dao/arena2 rooms/32room_000 random/random512-25-0
                              cities/Berlin_0_256 cities/Paris_0_1024 mazes/maze512-4-0)
datasets=$(sed -n 's/^MBOT_DATASETS_DIR:[A-Z]*=//p' build/CMakeCache.txt)
bin=build/apps/mbot_nav/mbot_nav
mkdir -p "$out"
printf "| map | queries | Warthog A*, mean µs | ours (A*), mean µs | ours ÷ Warthog | expansions ours / Warthog |\n|---|---|---|---|---|---|\n"
for m in "${maps[@]}"; do
  n=$(basename "$m")
  scen="$datasets/movingai/scenarios/$m.map.scen"
  "$warthog" --alg astar --scen "$scen" --map "$datasets/movingai/maps/$m.map" > "$out/$n.warthog.tsv" 2> /dev/null
  "$bin" --quiet --config config/movingai.ini --set source.path="$scen" --set movingai.search=astar \
    --set movingai.compare_astar=false --set output.dir="$out/ours_$n" --set pipeline.progress=off > /dev/null 2>&1
  awk -F'\t' -v n="$n" -v ours="$out/ours_$n/results.csv" '
    NR > 1 { wt += $8 / 1000; we += $3; q++ }
    END {
      while ((getline line < ours) > 0) { if (line ~ /^index/) continue; split(line, f, ","); ot += f[7]; oe += f[6]; oq++ }
      printf "| %s | %d | %.1f | %.1f | %.2f | %.3f |\n", n, q, wt / q, ot / oq, (ot / oq) / (wt / q), oe / we
    }' "$out/$n.warthog.tsv"
done
