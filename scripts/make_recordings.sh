#!/usr/bin/env bash
# Regenerates the recorded exchanges the integration tests replay (tests/integration/data):
# runs the tiny coupled scene with --record and keeps its recording and coupling history.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-$ROOT/build}
OUT=$(mktemp -d)
/usr/bin/python3 "$ROOT/scripts/launch.py" "$ROOT/tests/integration/data/tiny_coupled.yaml" \
  --build-dir "$BUILD_DIR" --run-dir "$OUT" --record --run-id tiny-recorded
cp "$OUT/exchanges.angiorec" "$ROOT/tests/integration/data/tiny_coupled.angiorec"
cp "$OUT/coupling.csv" "$ROOT/tests/integration/data/tiny_coupled.coupling.csv"
echo "make_recordings: wrote tests/integration/data/tiny_coupled.{angiorec,coupling.csv}"
rm -rf "$OUT"
