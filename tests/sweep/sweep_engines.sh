#!/bin/bash
# One sweep of config/sweep_mazes.ini run three ways — one job after another, under GNU parallel on
# every core, and as a Slurm job array on a one-node cluster started here — must give the same
# merged table. `local` (generated mazes 1-3 x seeds 1, 2): serial against GNU parallel, a re-run
# that skips the complete jobs and runs only the one whose outputs went missing, and a failing job
# named in the table. `slurm` (mazes 1-3 and 6 x seeds 1, 2): the job array against serial and
# GNU parallel.
#   tests/sweep/sweep_engines.sh <mbot_nav> <source dir> [local|slurm]
set -uo pipefail
bin=$1 src=$2 part=${3:-local}
work=$(mktemp -d /tmp/mbot_sweep_test.XXXXXX)
here=$(cd "$(dirname "$0")" && pwd)
cleanup() { [ -n "${slurm_dir:-}" ] && slurm_stop "$slurm_dir"; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }
cd "$src" || exit 1

expand() {  # folder mazes jobs [more arguments]
  "$bin" --config config/sweep_mazes.ini --set sweep.mazes="$2" --set sweep.seeds=1,2 --set output.dir="$1" "${@:4}" \
    > "$1.expand.log" 2>&1 || fail "expanding the sweep: $(cat "$1.expand.log")"
  [ "$(wc -l < "$1/jobs.txt")" = "$3" ] || fail "$1/jobs.txt has $(wc -l < "$1/jobs.txt") lines, not $3"
}
merge() {  # folder jobs
  "$bin" --quiet --config config/merge_sweep.ini --set source.path="$1" --set output.dir="$1.merge" || fail "merging $1"
  [ -s "$1/sweep.md" ] && [ -s "$1/sweep.csv" ] || fail "$1: no sweep.md / sweep.csv"
  grep -q "^# Sweep sweep_mazes: $2 jobs, 0 failed, 0 not run" "$1/sweep.md" || fail "$1/sweep.md: $(head -n 1 "$1/sweep.md")"
}

if [ "$part" = local ]; then
  parallel --version 2> /dev/null | grep -q "GNU parallel" || fail "GNU parallel is not installed (scripts/install_deps.sh)"
  expand "$work/serial" 1-3 6
  bash "$work/serial/jobs.txt" > "$work/serial.log" 2>&1 || fail "a serial job failed: $(tail -n 3 "$work/serial.log")"
  merge "$work/serial" 6

  expand "$work/parallel" 1-3 6
  parallel --retries 3 --joblog "$work/parallel/parallel.log" -a "$work/parallel/jobs.txt" \
    || fail "GNU parallel: a job failed (joblog: $(cat "$work/parallel/parallel.log"))"
  merge "$work/parallel" 6
  diff "$work/serial/sweep.md" "$work/parallel/sweep.md" || fail "GNU parallel's table differs from the serial run's"
  echo "serial and GNU parallel: the same table"

  # Resume: every job complete but one whose score went missing; only that one runs again.
  rm "$work/parallel/jobs/maze-3_seed-2/score.json"
  out=$(parallel --retries 3 -a "$work/parallel/jobs.txt") || fail "re-run failed"
  [ "$(grep -c 'complete, skipped' <<< "$out")" = 5 ] || fail "re-run skipped $(grep -c 'complete, skipped' <<< "$out") jobs, not 5"
  merge "$work/parallel" 6
  diff "$work/serial/sweep.md" "$work/parallel/sweep.md" || fail "the resumed sweep's table differs"
  echo "re-run: 5 complete jobs skipped, the one with a missing score.json run again, the same table"

  # A failing job: named in the table with its last log line; the others still merge.
  expand "$work/broken" 3 2
  sed -i '1s/--set pipeline.seed=1/--set pipeline.seed=-1/' "$work/broken/jobs.txt"
  bash "$work/broken/jobs.txt" > /dev/null 2>&1
  "$bin" --quiet --config config/merge_sweep.ini --set source.path="$work/broken" --set output.dir="$work/broken.merge" 2> /dev/null || fail "merging a sweep with a failed job"
  grep -q '^# Sweep sweep_mazes: 2 jobs, 1 failed, 0 not run' "$work/broken/sweep.md" || fail "broken: $(head -n 1 "$work/broken/sweep.md")"
  grep -q '^| maze-3_seed-1 | failed | exit status 2 | .*pipeline.*seed' "$work/broken/sweep.md" \
    || fail "the failed job is not named with its last log line: $(tail -n 2 "$work/broken/sweep.md")"
  echo "a failed job: named with its exit status and last log line"
  exit 0
fi

# Slurm: a one-node cluster with 2 CPUs, the same sweep as one job array.
source "$here/slurm_cluster.sh"
slurm_dir="$work/cluster"
if ! slurm_start "$slurm_dir" 2 > "$work/slurm_start.log" 2>&1; then
  echo "SKIPPED: the Slurm daemons cannot start here: $(cat "$work/slurm_start.log")"
  exit 77
fi
expand "$work/slurm" 1-3,6 8 --set sweep.slurm_lines_per_task=1  # the array index picks the line
expand "$work/serial" 1-3,6 8
bash "$work/serial/jobs.txt" > /dev/null 2>&1 || fail "a serial job failed"
merge "$work/serial" 8
expand "$work/parallel" 1-3,6 8
parallel --retries 3 -a "$work/parallel/jobs.txt" > /dev/null || fail "GNU parallel: a job failed"
merge "$work/parallel" 8
# Submitted, then watched every half second (sbatch --wait polls ever more slowly); 5 minutes at most.
job=$(sbatch --parsable "$work/slurm/sweep.sbatch" 2> "$work/sbatch.log") \
  || fail "sbatch: $(cat "$work/sbatch.log"); $(tail -n 5 "$slurm_dir/log/slurmctld.log")"
start=$(date +%s.%N)
queued() {  # the array's tasks still queued or running; fails the test when squeue cannot answer
  local out
  out=$(squeue -h -j "$job" 2>&1) || fail "squeue: $out"
  [ -n "$out" ]
}
for i in $(seq 1 600); do
  queued || break
  sleep 0.5
done
queued && fail "the array is still queued after 5 minutes: $(squeue)"
echo "Slurm: 8 array tasks of job $job in $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s"
for d in "$work"/slurm/jobs/*/; do
  grep -q '^0 ' "$d/exit_status" 2> /dev/null || fail "job $(basename "$d") did not end well: $(tail -n 2 "$d/job.log")"
done
[ "$(ls "$work/slurm/slurm" | wc -l)" = 8 ] || fail "Slurm ran $(ls "$work/slurm/slurm" | wc -l) array tasks, not 8"
merge "$work/slurm" 8
diff "$work/serial/sweep.md" "$work/slurm/sweep.md" || fail "the Slurm array's table differs from the serial run's"
diff "$work/parallel/sweep.md" "$work/slurm/sweep.md" || fail "the Slurm array's table differs from GNU parallel's"
echo "Slurm job array: the same table as the serial run's and GNU parallel's"
exit 0
