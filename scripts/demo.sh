#!/usr/bin/env bash
# Installs what the atlas program needs, builds just that program, cooks
# examples/quickstart.yaml, previews it and says where the outputs are.
# (scripts/test.sh installs and builds the rest.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --demo
bash scripts/build.sh --program-only
OUT="${1:-demo-out}"
mkdir -p "$OUT"
echo "cooking examples/quickstart.yaml into $OUT/ ..." >&2
build/bin/atlas cook examples/quickstart.yaml --out "$OUT" --report "$OUT/report.json"
echo "rendering a preview of the cooked NVDF set ..." >&2
build/bin/atlas preview examples/quickstart.yaml -o "$OUT/preview.png" --size 960x540
echo >&2
echo "outputs are in $(cd "$OUT" && pwd):" >&2
ls -1 "$OUT" | sed 's/^/  /' >&2
echo "the cook report (per node time, status, metrics) is $OUT/report.json" >&2
echo "look at $OUT/preview.png (the rendered clouds) and $OUT/density_slices.png (every z slice)" >&2
echo "demo done in ${SECONDS} s; next: docs/tutorial.md" >&2
