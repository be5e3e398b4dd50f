#!/usr/bin/env bash
# Checks that every tracked C++ file is formatted with the project's .clang-format (exit 1 and the
# offending files otherwise). Fix with: clang-format -i $(git ls-files '*.cpp' '*.hpp')
set -uo pipefail
cd "$(dirname "$0")/.."
command -v clang-format > /dev/null || { echo "SKIPPED: clang-format is not installed (scripts/install_deps.sh installs it)"; exit 77; }
if git rev-parse --git-dir > /dev/null 2>&1; then
  files=$(git ls-files '*.cpp' '*.hpp')
else
  files=$(find apps libs tests -name '*.cpp' -o -name '*.hpp')
fi
# One clang-format for all files; its warnings name each file that differs.
if ! out=$(clang-format --dry-run -Werror $files 2>&1); then
  echo "not formatted with .clang-format:"
  echo "$out" | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error:.*/  \1/p' | sort -u
  exit 1
fi
echo "format: $(echo "$files" | wc -w) files formatted"
