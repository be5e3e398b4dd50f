#!/usr/bin/env bash
# Builds the project with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/ (-O1, with
# debug info; the benchmarks and the live tests are not built) and runs the unit tests and the fast dataset regressions under them: a leak, an
# out-of-bounds access, a use after free or scope, a signed overflow or any other undefined
# behaviour fails the test that hit it. The Moving AI sweep and the live tests are left out (slow
# under the sanitizers; the live ones need real time).
#   scripts/sanitize.sh [extra ctest arguments]
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" \
  -DMBOT_SANITIZE=ON
cmake --build build-asan --target mbot_nav mbot_unit_tests mbot_sim_tests mbot_regression_tests
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:fast_unwind_on_malloc=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Leaks inside third-party libraries (libgphoto2, libusb, under OpenCV's VideoCapture), by name: tests/lsan.supp.
export LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp
ctest --test-dir build-asan --output-on-failure -j2 -L 'unit|regression|simulation' -LE 'movingai|live' "$@"
