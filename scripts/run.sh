#!/usr/bin/env bash
# Sets up the machine, builds, and runs a scene (default: the beam-only stent expansion; the
# coupled straight free expansion does not yet complete, see README "Status").
#   scripts/run.sh [SCENE] [launcher options, see scripts/launch.py --help]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
"$ROOT/scripts/setup.sh"
"$ROOT/scripts/build.sh"
SCENE=${1:-$ROOT/configs/beam_stent_radial_expansion.yaml}
shift || true
exec /usr/bin/python3 "$ROOT/scripts/launch.py" "$SCENE" --build-dir "${BUILD_DIR:-$ROOT/build}" "$@"
