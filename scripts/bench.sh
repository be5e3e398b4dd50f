#!/usr/bin/env bash
# Runs every benchmark of the project and prints one table of ratios, each measured in this run:
# ours against the library doing the same job (OpenCV, MRPT, aruco, a textbook A*), against our
# own simpler variant (A* for jump point search, a rebuild for the incremental update, scalar for
# AVX2), and against the limit (the particle filter against the plain lookup loop). BENCHMARKS.md
# shows the same table.
#   scripts/bench.sh [repetitions (default 3)] [out_dir (default out/bench)]
# Environment: MBOT_DATASETS_DIR (default ../shared/datasets), MOVINGAI_SAMPLE_EVERY (default 25:
# every 25th scenario of each of the 19 Moving AI files; 1 runs all 62,186, about an hour).
# Needs a Release build (scripts/build.sh). Takes about 3 minutes at the defaults on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
reps=${1:-3}
out=${2:-out/bench}
sample=${MOVINGAI_SAMPLE_EVERY:-25}
datasets=${MBOT_DATASETS_DIR:-$PWD/../shared/datasets}
b=build/tests
for exe in $b/mbot_planning_benchmark $b/mbot_slam_benchmark $b/mbot_vision_benchmark build/apps/mbot_nav/mbot_nav; do
  [ -x "$exe" ] || { echo "bench.sh: $exe is missing: build first (scripts/build.sh)" >&2; exit 1; }
done
mkdir -p "$out"

gbench() {  # name binary filter: medians of $reps repetitions, as CSV
  echo "bench.sh: $2 ($3) ..." >&2
  # JSON: Google Benchmark's CSV writer refuses runs whose counters differ (the SLAM benchmark's do).
  MBOT_DATASETS_DIR=$datasets "$b/$2" --benchmark_filter="$3" --benchmark_repetitions="$reps" \
    --benchmark_report_aggregates_only=true --benchmark_out="$out/$1.json" --benchmark_out_format=json \
    >"$out/$1.log" 2>&1 || {
    echo "bench.sh: $2 failed, see $out/$1.log" >&2
    exit 1
  }
}
gbench planning mbot_planning_benchmark '.'
gbench slam mbot_slam_benchmark 'ParticleFilter|LookupBound|ScanPrepare'
gbench vision mbot_vision_benchmark '.'

echo "bench.sh: Moving AI, every ${sample}th scenario, jump point search and A* on each ..." >&2
for scen in "$datasets"/movingai/scenarios/*/*.map.scen; do
  name=$(basename "$scen" .map.scen)
  build/apps/mbot_nav/mbot_nav --quiet --config config/movingai.ini --set "source.path=$scen" \
    --set "output.dir=$out/movingai/$name" --set pipeline.progress=off --set movingai.compare_astar=true \
    --set "movingai.sample_every=$sample" >"$out/movingai_$name.log" 2>&1 || {
    echo "bench.sh: Moving AI $name failed (not optimal?), see $out/movingai_$name.log" >&2
    exit 1
  }
done

# One table. `median NAME FILE` prints the median real time of benchmark NAME in ms.
median() {
  awk -v n="\"$1_median\"," '
    $1 == "\"name\":" { hit = ($2 == n) }
    hit && $1 == "\"real_time\":" { t = $2 + 0 }
    hit && $1 == "\"time_unit\":" {
      u = $2; gsub(/[",]/, "", u)
      if (u == "us") t /= 1000; else if (u == "ns") t /= 1e6; else if (u == "s") t *= 1000
      printf "%.4f", t; found = 1; hit = 0 }
    END { if (!found) printf "nan" }' "$out/$2.json"
}
row() {  # what ours baseline baseline-name: ratio = baseline / ours (above 1: ours is faster)
  awk -v w="$1" -v a="$2" -v b="$3" -v n="$4" 'BEGIN {
    r = (a + 0 > 0 && b + 0 > 0) ? sprintf("%.2f", b / a) : "n/a"
    fmt = (a + 0 < 1) ? "%.3f" : "%.1f"
    printf "| %s | " fmt " ms | " fmt " ms | %s | %s |\n", w, a, b, n, r }'
}
P=planning S=slam V=vision
echo
echo "| what | ours | baseline | baseline is | baseline ÷ ours |"
echo "|---|---:|---:|---|---:|"
row "distance transform, 800×800 arena" "$(median BM_DistanceGrid_Ours/0 $P)" "$(median BM_DistanceGrid_OpenCV/0 $P)" "OpenCV distanceTransform (exact)"
row "distance transform, 2000×2000 world" "$(median BM_DistanceGrid_Ours/1 $P)" "$(median BM_DistanceGrid_OpenCV/1 $P)" "OpenCV distanceTransform (exact)"
row "distance transform, 800×800 arena" "$(median BM_DistanceGrid_Ours/0 $P)" "$(median BM_DistanceGrid_Brushfire/0 $P)" "8-neighbour brushfire (the reports')"
for r in 20 60; do
  row "map update (disk of $r cells) → distances + planner" "$(median BM_MapUpdate_Incremental/$r $P)" \
    "$(median BM_MapUpdate_Rebuild/$r $P)" "rebuild both"
done
for m in 0 1 2 3 4; do
  names=(convex empty maze narrow wide)
  row "A* per botlab query, ${names[$m]}" "$(median BM_AStar_Ours/$m $P)" "$(median BM_AStar_Textbook/$m $P)" "textbook A*"
done
for n in 1000 10000 100000; do
  ours1=$(median "BM_ParticleFilter_Ours/particles:$n/threads:1/real_time" $S)
  bound=$(median "BM_LookupBound/particles:$n/real_time" $S)
  row "particle filter $n, 1 thread" "$ours1" "$bound" "lookup loop, 1 core (the limit)"
  row "particle filter $n, 2 threads" "$(median "BM_ParticleFilter_Ours/particles:$n/threads:0/real_time" $S)" \
    "$(awk -v b="$bound" 'BEGIN { printf "%.4f", b / 2 }')" "lookup loop ÷ 2 cores (the limit)"
  row "particle filter $n, 1 thread" "$ours1" "$(median "BM_ParticleFilter_MRPT/particles:$n/real_time" $S)" "MRPT CMonteCarloLocalization2D"
done
for n in 1000 100000; do
  row "particle filter $n, 1 thread, AVX2" "$(median "BM_ParticleFilter_Ours/particles:$n/threads:1/real_time" $S)" \
    "$(median "BM_ParticleFilter_OursScalar/particles:$n/threads:1/real_time" $S)" "ours, scalar"
done
row "AprilTag, library photo 799×533" "$(median BM_Photo_Reference_Decimate1 $V)" "$(median BM_Photo_Aruco_Subpix $V)" "OpenCV aruco 36h11 (subpixel)"
row "AprilTag, simulated 640×480" "$(median BM_Sim640_Reference_Decimate2 $V)" "$(median BM_Sim640_Aruco_Subpix $V)" "OpenCV aruco 36h11 (subpixel)"
for s in "$out"/movingai/*/summary.json; do
  name=$(basename "$(dirname "$s")")
  sed -E 's/.*"time_us": \{[^}]*"mean": ([0-9.e+-]+)[^}]*\}.*"astar": \{[^}]*"time_us": \{[^}]*"mean": ([0-9.e+-]+).*/\1 \2/' "$s" |
    while read -r jps astar; do
      row "Moving AI $name (mean per query)" "$(awk -v v="$jps" 'BEGIN { printf "%.4f", v / 1000 }')" \
        "$(awk -v v="$astar" 'BEGIN { printf "%.4f", v / 1000 }')" "our A* (jump point search ÷ A*)"
    done
done
echo
echo "(medians of $reps repetitions of each benchmark; Moving AI: every ${sample}th scenario, both optimal on every one;"
echo " raw results in $out)"
