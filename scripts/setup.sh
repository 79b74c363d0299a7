#!/usr/bin/env bash
# Installs Atlas's dependencies from Debian 12 packages.
# Idempotent: packages already present are not reinstalled, and apt is not
# touched at all when nothing is missing. Must run as root (or via sudo).
# Usage: scripts/setup.sh [--demo | --bench]
#   --demo   only what building the atlas program needs (scripts/demo.sh)
#   (none)   every build and test dependency (scripts/test.sh, CI)
#   --bench  also the peers the benchmarks compare against
set -euo pipefail

# The atlas program and the libraries it links (scripts/demo.sh builds just that).
DEMO_PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config
  libopenvdb-dev libopenexr-dev libimath-dev libopenimageio-dev libpng-dev
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev libboost-iostreams-dev
  libtet1.5-dev libtbb-dev libyaml-cpp-dev zlib1g-dev libblosc-dev nlohmann-json3-dev
  libwebp-dev
)
PACKAGES=(
  "${DEMO_PACKAGES[@]}"
  git openimageio-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  libsquish-dev libcgal-demo
  # libFuzzer targets (tests/fuzz/): clang 14 and its fuzzer runtime.
  clang libclang-rt-14-dev libfuzzer-14-dev
  # Independent readers for the engine-import test (tests/engine_import/): OpenImageIO's
  # and OpenVDB's own Python bindings for the system Python 3.11, and pytest.
  python3-openimageio python3-openvdb python3-numpy python3-pytest
  # The atlas Python module (python/) for the same system Python, and its headers; its wheel
  # (pyproject.toml) is built and installed into a virtual environment with Debian's tools.
  pybind11-dev python3-dev python3-pip python3-setuptools python3-wheel python3-venv
  # The tile-sharded cook's cluster driver (python/atlas_dask, docs/scale.md): Dask and distributed 2022.12.
  python3-dask python3-distributed
  # The Blender add-on's headless test (plugins/blender/): Debian's Blender 3.4 runs the same Python.
  blender
  # Independent WebP readers (Pillow, webpmux) for the animation test (tests/render/animation_test.py).
  webp python3-pil
  # The Cycles reference (scripts/cycles_reference.py, bench/render_vs_cycles.sh): its error plots.
  python3-matplotlib
  # docs/images/architecture.svg (scripts/module_graph.py | dot): the module dependency picture.
  graphviz
  chromium
)
# atlas view's page (plugins/web) is bundled from npm packages; Node.js >= 18 builds it.
command -v npm >/dev/null || PACKAGES+=(nodejs npm)
# `scripts/setup.sh --bench`: also the peers the benchmarks compare against (not needed by CI):
# OpenVDB's vdb_tool and vdb_render (mesh SDF, voxel preview) and nvcompress (BC encoders).
case "${1:-}" in
  --bench) PACKAGES+=(libopenvdb-tools libnvtt-bin) ;;
  --demo) PACKAGES=("${DEMO_PACKAGES[@]}") ;;
  "") ;;
  *) echo "setup: unknown option '$1' (expected --demo or --bench)" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present" >&2
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi

echo "setup: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
echo "setup: done" >&2
