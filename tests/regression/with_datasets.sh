#!/bin/bash
# Runs a command that needs the shared datasets. Without them: fail under CI=true, otherwise report
# the test as skipped (exit 77, ctest SKIP_RETURN_CODE) with the reason.
dir="${MBOT_DATASETS_DIR:?MBOT_DATASETS_DIR is not set}"
if [ ! -d "$dir/botlab" ] || [ ! -d "$dir/movingai" ]; then
  if [ "${CI:-}" = "true" ]; then echo "FAIL: shared datasets not found at $dir (set MBOT_DATASETS_DIR)"; exit 1; fi
  echo "SKIPPED: shared datasets not found at $dir (set MBOT_DATASETS_DIR)"; exit 77
fi
exec "$@"
