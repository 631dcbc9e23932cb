#!/usr/bin/env bash
# Sets up the machine, builds, and runs a scene (default: the straight free stent expansion of
# the paper, §3.1: coupler + beam_solver + solid_solver, about a minute on 2 cores after the build).
#   scripts/run.sh [SCENE] [launcher options, see scripts/launch.py --help]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
"$ROOT/scripts/setup.sh"
"$ROOT/scripts/build.sh"
SCENE=${1:-$ROOT/configs/straight_free_expansion.yaml}
shift || true
exec /usr/bin/python3 "$ROOT/scripts/launch.py" "$SCENE" --build-dir "${BUILD_DIR:-$ROOT/build}" "$@"
