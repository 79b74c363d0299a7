#!/usr/bin/env bash
# Makes docs/images/tutorial_*.png by running docs/tutorial.md's commands as written (the same
# runner as the doc_commands test) with the Release build, then copying the pictures it made.
#   scripts/make_tutorial_images.sh [BUILD_DIR]   (default build/)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 tests/docs/run_doc_commands.py --source . --build "$build" --only docs/tutorial.md --keep "$work/run"
t="$work/run/tut"
cp "$t/out/top.png" docs/images/tutorial_density_top.png
cp "$t/cumulus.png" docs/images/tutorial_cumulus.png
cp "$t/cumulus_orbit.png" docs/images/tutorial_cumulus_orbit.png
cp "$t/cumulus_towers.png" docs/images/tutorial_cumulus_towers.png
cp "$t/out/density_bc4_slice.png" docs/images/tutorial_density_bc4_slice.png
cp "$t/storm/storm_coverage.png" docs/images/tutorial_storm_coverage.png
cp "$t/storm_aerial.png" docs/images/tutorial_storm_aerial.png
cp "$t/storm_ground.png" docs/images/tutorial_storm_ground.png
ls -l docs/images/tutorial_*.png >&2
