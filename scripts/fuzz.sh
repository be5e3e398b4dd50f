#!/usr/bin/env bash
# Fuzzes one parser (or all of them) with libFuzzer under AddressSanitizer + UndefinedBehaviorSanitizer.
#   scripts/fuzz.sh TARGET SECONDS     e.g. scripts/fuzz.sh carmen 60
#   scripts/fuzz.sh all SECONDS        every target in turn, SECONDS each
#   scripts/fuzz.sh list               the targets
# Builds build-fuzz/ with clang (-DMBOT_FUZZ=ON, -O1 -g), replays the target's regression inputs
# (tests/fuzz/regressions/TARGET: the crash reproducers, some as patches to a shared dataset), then
# fuzzes from the seeds tests/fuzz/seeds.txt names (read from the shared datasets, first 64 KiB) plus
# the corpus it grew before (build-fuzz/fuzz/corpus/TARGET). A crash, sanitizer report, leak,
# timeout (10 s an input) or an input needing more than 2 GB fails the run, and libFuzzer writes the
# input to build-fuzz/fuzz/findings/TARGET/ — add it to the regressions once fixed.
# Environment: MBOT_DATASETS_DIR (default ../shared/datasets), MBOT_FUZZ_BUILD_DIR (build-fuzz),
# MBOT_FUZZ_NO_BUILD=1 (ctest: the build is current).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
targets=(lcm_log lcm_messages rawlog carmen botlab_map pgm_yaml gridmap simplemap movingai_map
  movingai_scenarios motor_csv ini mcap cdr ros1_bag arena camera_yaml relations image_folder)

usage() { sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
[ $# -ge 1 ] || usage
if [ "$1" = list ]; then printf '%s\n' "${targets[@]}"; exit 0; fi
[ $# -eq 2 ] || usage
target=$1
seconds=$2
[[ "$seconds" =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number, not '$seconds'" >&2; exit 2; }
if [ "$target" != all ] && ! printf '%s\n' "${targets[@]}" | grep -qx "$target"; then
  echo "fuzz.sh: no target '$target' (scripts/fuzz.sh list)" >&2
  exit 2
fi

build=${MBOT_FUZZ_BUILD_DIR:-$root/build-fuzz}
datasets=${MBOT_DATASETS_DIR:-$root/../shared/datasets}
if [ "${MBOT_FUZZ_NO_BUILD:-0}" != 1 ]; then
  ./scripts/install_deps.sh --fuzz
  mkdir -p "$build"
  CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" -DMBOT_FUZZ=ON -DMBOT_BUILD_TESTS=OFF \
    "-DMBOT_DATASETS_DIR=$datasets" > "$build/configure.log" 2>&1 ||
    { cat "$build/configure.log"; exit 1; }
  if [ "$target" = all ]; then cmake --build "$build" --target fuzz_targets; else cmake --build "$build" --target "fuzz_$target"; fi
fi

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# The seeds of one target, read fresh into $build/fuzz/seeds/TARGET.
make_seeds() {
  local t=$1 dir=$build/fuzz/seeds/$1 n=0
  rm -rf "$dir" && mkdir -p "$dir"
  while read -r name path; do
    [ "$name" = "$t" ] || continue
    local file
    if [[ "$path" == repo:* ]]; then file=$root/${path#repo:}; else file=$datasets/$path; fi
    [ -f "$file" ] || { echo "fuzz.sh: seed $file is missing (tests/fuzz/seeds.txt)" >&2; continue; }
    n=$((n + 1))
    if [[ "$file" == *.gz ]]; then
      { gzip -dc "$file" || true; } | head -c 65536 > "$dir/seed_$n"
    else
      head -c 65536 "$file" > "$dir/seed_$n"
    fi
  done < <(grep -v '^#' tests/fuzz/seeds.txt)
  case $t in
    pgm_yaml)
      { printf 'image: map.pgm\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\n'
        printf 'occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n\0P5\n8 4\n255\n'
        head -c 32 /dev/zero | tr '\0' '\376'; } > "$dir/seed_trinary"
      { printf 'image: map.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 1\nmode: scale\n\0P2\n3 2\n255\n'
        printf '0 128 255\n255 0 7\n'; } > "$dir/seed_scale" ;;
    image_folder)  # a small PNG and JPEG of an AprilTag test photo's kind: the first byte picks the name
      python3 - "$dir" <<'PY'
import struct, sys, zlib
d = sys.argv[1]
w, h = 16, 8
raw = b"".join(b"\0" + bytes((x * 16) & 255 for x in range(w)) for _ in range(h))
def chunk(t, b): return struct.pack(">I", len(b)) + t + b + struct.pack(">I", zlib.crc32(t + b) & 0xffffffff)
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
open(d + "/seed_png", "wb").write(b"\0" + png)
open(d + "/seed_pgm", "wb").write(b"\3" + b"P5\n%d %d\n255\n" % (w, h) + bytes(w * h))
PY
      ;;
    movingai_scenarios)
      printf 'version 1\n0\ttiny.map\t8\t8\t0\t0\t7\t7\t9.89949494\n0\ttiny.map\t8\t8\t0\t7\t7\t0\t9.89949494\n' \
        > "$dir/seed_tiny" ;;
    mcap | cdr | ros1_bag)  # small bags of every message type, each type's CDR, ROS 1 bags of Intel's first messages
      local tmp=$build/fuzz/seeds/ros2_all
      rm -rf "$tmp" && mkdir -p "$tmp"
      MBOT_FUZZ_SEED_DIR=$tmp MBOT_FUZZ_ROS1_BAG=$datasets/carmen/intel.orig.bag \
        "$build/tests/fuzz/fuzz_$t" -runs=0 "$tmp" > /dev/null 2>&1 || true
      local prefix=bag
      [ "$t" = cdr ] && prefix=cdr
      [ "$t" = ros1_bag ] && prefix=ros1
      cp "$tmp"/seed_"$prefix"* "$dir"/ 2>/dev/null || true ;;
    lcm_messages)
      MBOT_FUZZ_CARVE="$datasets/botlab/modern_small_logs/f23_lcmlog-2023-11-07.00:$datasets/botlab/modern_small_logs/w22_lcmlog-2022-02-14.04:$datasets/botlab/modern_small_logs/w25_mbot_square_log.log:$datasets/botlab/legacy_2017/sweep_drive_square_10mx10m_5cm.log:$datasets/botlab/legacy_2017/maebot_convex.log" \
        MBOT_FUZZ_CARVE_DIR=$dir "$build/tests/fuzz/fuzz_lcm_messages" -runs=0 "$dir" > /dev/null 2>&1 || true ;;
  esac
}

# Regression inputs of one target into $build/fuzz/regressions/TARGET: files as they are, and
# *.patch files ("base <dataset path>", "gunzip", "set <offset> <hex bytes>", "truncate <bytes>")
# applied to a fresh copy of their base.
make_regressions() {
  local t=$1 src=$root/tests/fuzz/regressions/$1 dir=$build/fuzz/regressions/$1
  rm -rf "$dir" && mkdir -p "$dir"
  [ -d "$src" ] || return 0
  for f in "$src"/*; do
    [ -f "$f" ] || continue
    local out=$dir/$(basename "$f")
    if [[ "$f" != *.patch ]]; then cp "$f" "$out"; continue; fi
    out=${out%.patch}
    while read -r op a b; do
      case $op in
        base) [ -f "$datasets/$a" ] || { echo "fuzz.sh: $f: base $datasets/$a is missing" >&2; rm -f "$out"; break; }
              cp "$datasets/$a" "$out" && chmod u+w "$out" ;;
        gunzip) gzip -dc < "$out" > "$out.tmp" && mv "$out.tmp" "$out" ;;
        set) printf "$(echo "$b" | sed 's/../\\x&/g')" | dd of="$out" bs=1 seek="$a" conv=notrunc status=none ;;
        truncate) truncate -s "$a" "$out" ;;
        *) echo "fuzz.sh: $f: unknown patch line '$op'" >&2; exit 2 ;;
      esac
    done < "$f"
  done
}

run_one() {
  local t=$1 bin=$build/tests/fuzz/fuzz_$1
  [ -x "$bin" ] || { echo "fuzz.sh: $bin is not built" >&2; exit 1; }
  make_seeds "$t"
  make_regressions "$t"
  local corpus=$build/fuzz/corpus/$t findings=$build/fuzz/findings/$t
  mkdir -p "$corpus" "$findings"
  local common=(-rss_limit_mb=2048 -malloc_limit_mb=1000000 -timeout=10 -max_len=65536 "-artifact_prefix=$findings/")
  local n_reg
  n_reg=$(find "$build/fuzz/regressions/$t" -type f | wc -l)
  echo "== $t: $n_reg regression inputs"
  if [ "$n_reg" -gt 0 ]; then
    "$bin" "${common[@]}" "$build/fuzz/regressions/$t"/* > "$build/fuzz/$t.regressions.log" 2>&1 ||
      { tail -40 "$build/fuzz/$t.regressions.log"; echo "fuzz.sh: $t: a regression input fails" >&2; exit 1; }
  fi
  echo "== $t: fuzzing $seconds s from $(find "$build/fuzz/seeds/$t" -type f | wc -l) seeds and $(find "$corpus" -type f | wc -l) corpus inputs"
  if ! "$bin" "${common[@]}" -max_total_time="$seconds" -print_final_stats=1 "$corpus" "$build/fuzz/seeds/$t" \
      > "$build/fuzz/$t.log" 2>&1; then
    tail -60 "$build/fuzz/$t.log"
    echo "fuzz.sh: $t: finding written to $findings/" >&2
    exit 1
  fi
  grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb' "$build/fuzz/$t.log" | tr '\n' ' ' | sed "s/^/== $t: /"
  echo
}

if [ "$target" = all ]; then
  for t in "${targets[@]}"; do run_one "$t"; done
else
  run_one "$target"
fi
