#!/usr/bin/env bash
# The 100-maze sweep (config/sweep_mazes.ini, mazes 1-100, seed 1) three ways on this machine: one
# job after another, GNU parallel on every core, and a Slurm job array on a one-node cluster with
# every core as its CPUs (started here, as tests/sweep does), one, ten and fifty jobs per array task
# (slurm_lines_per_task). Prints wall times, the speed-ups against
# the serial run, the scheduler's overhead per job against GNU parallel, and whether the three merged
# tables are identical: the figures in BENCHMARKS.md "Sweeps". Run it on a quiet machine.
#   scripts/bench_sweep.sh [mazes (default 1-100)] [work dir]
set -euo pipefail
cd "$(dirname "$0")/.."
mazes=${1:-1-100}
work=${2:-out/bench_sweep}
bin=$PWD/build/apps/mbot_nav/mbot_nav
cpus=$(nproc)
rm -rf "$work" && mkdir -p "$work"
work=$(cd "$work" && pwd)
source tests/sweep/slurm_cluster.sh
trap 'slurm_stop "$work/cluster"' EXIT
now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
for e in serial parallel; do
  "$bin" --quiet --config config/sweep_mazes.ini --set sweep.mazes="$mazes" --set output.dir="$work/$e" > /dev/null
done
"$bin" --quiet --config config/sweep_mazes.ini --set sweep.mazes="$mazes" --set sweep.slurm_lines_per_task=1 \
  --set output.dir="$work/slurm" > /dev/null
for k in 10 50; do
  "$bin" --quiet --config config/sweep_mazes.ini --set sweep.mazes="$mazes" --set sweep.slurm_lines_per_task=$k \
    --set output.dir="$work/slurm$k" > /dev/null
done
n=$(wc -l < "$work/serial/jobs.txt")
t0=$(now); bash "$work/serial/jobs.txt" > /dev/null 2>&1 || true; t_serial=$(secs "$t0" "$(now)")
t0=$(now); parallel --retries 3 -a "$work/parallel/jobs.txt" > /dev/null || true; t_parallel=$(secs "$t0" "$(now)")
slurm_start "$work/cluster" "$cpus" > "$work/slurm_start.log" 2>&1 || { cat "$work/slurm_start.log"; exit 1; }
array() {  # folder: submits its array and waits for it; prints the wall time
  local t0 job
  t0=$(now)
  job=$(sbatch --parsable "$1/sweep.sbatch")
  local i
  for i in $(seq 1 36000); do  # two hours at most
    [ -n "$(squeue -h -j "$job")" ] || break
    sleep 0.2
  done
  secs "$t0" "$(now)"
}
t_slurm=$(array "$work/slurm")
t_slurm10=$(array "$work/slurm10")
t_slurm50=$(array "$work/slurm50")
for e in serial parallel slurm slurm10 slurm50; do
  "$bin" --quiet --config config/merge_sweep.ini --set source.path="$work/$e" --set output.dir="$work/$e.merge" 2> /dev/null
done
same=no
if cmp -s "$work/serial/sweep.md" "$work/parallel/sweep.md" && cmp -s "$work/serial/sweep.md" "$work/slurm/sweep.md" &&
  cmp -s "$work/serial/sweep.md" "$work/slurm10/sweep.md" && cmp -s "$work/serial/sweep.md" "$work/slurm50/sweep.md"; then
  same=yes
fi
echo "| engine | jobs | wall s | speed-up vs serial | overhead per job vs GNU parallel |"
echo "|---|---|---|---|---|"
echo "| serial (bash jobs.txt) | $n | $t_serial | 1.00 | |"
awk -v n="$n" -v s="$t_serial" -v p="$t_parallel" -v c="$cpus" 'BEGIN { printf "| GNU parallel, %d cores | %d | %.1f | %.2f | |\n", c, n, p, s / p }'
awk -v n="$n" -v s="$t_serial" -v p="$t_parallel" -v l="$t_slurm" -v c="$cpus" \
  'BEGIN { printf "| Slurm array, one node of %d CPUs, a job per task | %d | %.1f | %.2f | %.2f s |\n", c, n, l, s / l, (l - p) * c / n }'
awk -v n="$n" -v s="$t_serial" -v p="$t_parallel" -v l="$t_slurm10" -v c="$cpus" \
  'BEGIN { printf "| Slurm array, one node of %d CPUs, 10 jobs per task | %d | %.1f | %.2f | %.2f s |\n", c, n, l, s / l, (l - p) * c / n }'
awk -v n="$n" -v s="$t_serial" -v p="$t_parallel" -v l="$t_slurm50" -v c="$cpus" \
  'BEGIN { printf "| Slurm array, one node of %d CPUs, 50 jobs per task | %d | %.1f | %.2f | %.2f s |\n", c, n, l, s / l, (l - p) * c / n }'
echo "merged tables identical (serial, GNU parallel, every Slurm array): $same"
echo "the table: $work/serial/sweep.md"
