#!/usr/bin/env bash
# Mesh -> SDF of the CGAL armadillo (52k triangles) at 128^3, 256^3 and 384^3: Atlas's whole
# grid (method edt and method openvdb) against OpenVDB's meshToLevelSet with a 3-voxel band
# (what `vdb_tool -mesh2ls width=3` runs), in one volume_bench process with random
# interleaving (wall and process CPU of each, from the mesh in memory), then vdb_tool
# itself as a whole process (OBJ read included) at the same voxel sizes; medians and the
# fitted exponent of time against voxels. docs/PERFORMANCE.md has the figures.
# Usage: bench/mesh_sdf_vs_vdb_tool.sh [BUILD_DIR] [REPETITIONS]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
REPS="${2:-5}"
PY=/usr/bin/python3
OUT="$(mktemp -d /tmp/mesh_sdf_vs_vdb_tool.XXXXXX)"
tar -xzf /usr/share/doc/libcgal-demo/data.tar.gz -C "$OUT" data/meshes/armadillo.off
OFF="$OUT/data/meshes/armadillo.off"
# OBJ for vdb_tool (it reads no OFF): the same vertices and triangles.
awk 'NR==1{next} NR==2{nv=$1; next} nv>0{print "v",$1,$2,$3; nv--; next} NF==4{print "f",$2+1,$3+1,$4+1}' "$OFF" > "$OUT/armadillo.obj"
echo "load before: $(uptime)"
ATLAS_BENCH_ARMADILLO="$OFF" "$BUILD/bench/volume_bench" \
  --benchmark_filter='BM_Armadillo(AtlasEdt|AtlasOpenVdb|VdbMeshToLevelSet)/|BM_ArmadilloAccuracy' \
  --benchmark_repetitions="$REPS" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$OUT/bench.json" --benchmark_out_format=json > "$OUT/bench.txt" 2>&1
echo "load after bench: $(uptime)"
command -v vdb_tool > /dev/null || { echo "no vdb_tool (scripts/setup.sh --bench)" >&2; exit 1; }
: > "$OUT/vdb_tool.txt"
for r in $(seq "$REPS"); do
  for n in 128 256 384; do
    voxel=$($PY -c "print(160 / $n)")
    /usr/bin/time -f "$n %e %U %S %M" -a -o "$OUT/vdb_tool.txt" \
      vdb_tool -read "$OUT/armadillo.obj" -mesh2ls voxel="$voxel" width=3 > /dev/null
  done
done
echo "load after vdb_tool: $(uptime)"
$PY - "$OUT" <<'EOF'
import json, math, statistics, sys
out = sys.argv[1]
runs = json.load(open(out + "/bench.json"))["benchmarks"]
rows = {}
acc = {}
for b in runs:
    if b.get("run_type") != "iteration":
        continue
    name = b["run_name"].split("/")
    if name[0].startswith("BM_ArmadilloAccuracy"):
        acc[name[0]] = b
        continue
    key = (name[0].replace("BM_Armadillo", ""), int(name[1]))
    # real_time is wall (ms); cpu_time is process CPU (MeasureProcessCPUTime).
    rows.setdefault(key, []).append((b["real_time"] / 1e3, b["cpu_time"] / 1e3))
vt = {}
for line in open(out + "/vdb_tool.txt"):
    f = line.split()
    if len(f) == 5 and f[0].isdigit():
        vt.setdefault(("vdb_tool process", int(f[0])), []).append((float(f[1]), float(f[2]) + float(f[3])))
rows.update(vt)
def fit(xs, ys):
    lx = [math.log(x) for x in xs]; ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
print("| what | 128^3 wall / CPU s | 256^3 wall / CPU s | 384^3 wall / CPU s | exponent (wall, CPU) vs voxels |")
print("|---|---|---|---|---|")
for what in ["AtlasEdt", "AtlasOpenVdb", "VdbMeshToLevelSet", "vdb_tool process"]:
    cells, xs, ws, cs = [], [], [], []
    for n in (128, 256, 384):
        v = rows.get((what, n))
        if not v:
            cells.append("-"); continue
        w = statistics.median(x[0] for x in v); c = statistics.median(x[1] for x in v)
        cells.append(f"{w:.2f} / {c:.2f}"); xs.append(n ** 3); ws.append(w); cs.append(c)
    e = f"{fit(xs, ws):.2f}, {fit(xs, cs):.2f}" if len(xs) == 3 else "-"
    print(f"| {what} | " + " | ".join(cells) + f" | {e} |")
for k, b in acc.items():
    print(k, {c: b[c] for c in ("band_err_vox", "near_err_vox", "far_err_vox", "sign_err", "samples") if c in b})
EOF
echo "raw: $OUT"
