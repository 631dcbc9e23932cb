#!/usr/bin/env bash
# Installs what the project needs from Debian packages, if missing (idempotent), and checks for
# a Rust toolchain (cargo >= 1.75) to build the zenoh shim. Run as root or with sudo available.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread
  petsc-dev libopenmpi-dev openmpi-bin libhdf5-openmpi-dev libhdf5-dev
  flatbuffers-compiler libflatbuffers-dev libyaml-cpp-dev nlohmann-json3-dev libssl-dev
  libgtest-dev googletest
  python3 python3-numpy python3-scipy python3-matplotlib python3-h5py python3-yaml python3-gmsh python3-meshio
  # VTK XML PolyData (.vtp) lumen surfaces and centerlines (scripts/patient/surface_file.py)
  python3-vtk9
  # studies as Slurm job arrays (scripts/study.py --runner slurm); the test starts its own one-node cluster
  slurm-client slurmctld slurmd munge
  # participants in separate network namespaces (tests/integration/test_network_namespaces.py)
  iproute2
  # format and lint (scripts/lint.sh)
  clang-format black python3-flake8
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "setup: all Debian packages present"
fi

# cargo: from rustup (~/.cargo/bin) or the system; Debian bookworm's own cargo is too old for zenoh.
export PATH="$HOME/.cargo/bin:$PATH"
if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: error: cargo not found. The zenoh transport is a Rust crate built with cargo >= 1.75;" >&2
  echo "       install a Rust toolchain (e.g. rustup) and re-run." >&2
  exit 1
fi
v=$(cargo --version | awk '{print $2}')
major=${v%%.*}; rest=${v#*.}; minor=${rest%%.*}
if [ "$major" -lt 1 ] || { [ "$major" -eq 1 ] && [ "$minor" -lt 75 ]; }; then
  echo "setup: error: cargo $v is too old; the zenoh crate needs cargo >= 1.75 (found $(command -v cargo))" >&2
  exit 1
fi
echo "setup: cargo $v"

# The `angio` command (scripts/angio): a link in ~/.local/bin, which Debian's default ~/.profile puts
# on PATH once the directory exists.
if mkdir -p "$HOME/.local/bin" 2>/dev/null && ln -sf "$(cd "$(dirname "$0")" && pwd)/angio" "$HOME/.local/bin/angio"; then
  case ":$PATH:" in
    *":$HOME/.local/bin:"*) echo "setup: angio -> $HOME/.local/bin/angio" ;;
    *) echo "setup: angio -> $HOME/.local/bin/angio (not on PATH in this shell: open a new login shell, or use scripts/angio)" ;;
  esac
else
  echo "setup: could not link ~/.local/bin/angio; use scripts/angio"
fi
