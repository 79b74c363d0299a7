#!/usr/bin/env bash
# Issue 46 item 3: a world of the cloudscape kind at scale, cooked tile by tile on one machine.
# 16 km x 16 km x 512 m at 8 m voxels (2048 x 2048 x 64): cumulus grown by volume/billows from
# coarse spheres scattered over the world, splatted by volume/metaballs (a windowed generator:
# each tile splats the spheres that reach it), a flat base, noise erosion, an SDF clipped at 64 m
# (halo 9 voxels), the anatomy paint, the NVDF set, and 003's engine textures per tile: the
# modeling NVDF in BC6H and the field data in one-sided BC4. Writes the tile files and the
# index (no assembly and no exact copies: at this size the tiles are the product), then prints per-tile time and
# memory and the totals. Not run in CI (minutes); figures in docs/scale.md.
#   bench/scale_world.sh [ATLAS] [OUT_DIR] [TILES]      e.g. bench/scale_world.sh build/bin/atlas /tmp/sw 8,8
# SIZE (metres, default 16384) and RES (voxels, default 2048) scale the world; CLOUDS the count.
set -euo pipefail
atlas="${1:-build/bin/atlas}" out="${2:-/tmp/atlas-scale-world}" tiles="${3:-8,8}"
size="${SIZE:-16384}" res="${RES:-2048}" clouds="${CLOUDS:-64}"
rm -rf "$out" && mkdir -p "$out"
/usr/bin/python3 - "$size" "$res" "$clouds" > "$out/world.yaml" <<'PY'
import random, sys
size, res, clouds = float(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
rng = random.Random(46)
spheres = []
for _ in range(clouds):  # a cumulus: 4-7 coarse spheres around a centre, bases near 110 m
    cx, cy = rng.uniform(600, size - 600), rng.uniform(600, size - 600)
    for _ in range(rng.randint(4, 7)):
        r = rng.uniform(90, 200)
        spheres.append(f"{cx + rng.uniform(-250, 250):.0f} {cy + rng.uniform(-250, 250):.0f} {rng.uniform(150, 300):.0f} {r:.0f}")
grid = f"resolution: [{res}, {res}, 64], bounds_min: [0, 0, 0], bounds_max: [{size:.0f}, {size:.0f}, 512]"
print(f"""atlas: 1
description: bench/scale_world.sh's world ({size:.0f} m square, {res}^2 x 64 voxels, {clouds} cumulus)
nodes:
  shape:
    type: volume/billows
    params:
      spheres: "{'; '.join(spheres)}"
      levels: 2
      children: 10
      base_height: 110
      towers: 8
      tower_height: 60
      seed: 3
  density:
    type: volume/metaballs
    inputs: {{points: shape}}
    params: {{{grid}, kernel: sphere, blend: max}}
  based:
    type: volume/cutout
    inputs: {{in: density}}
    params: {{shape: box, a: [{size / 2:.0f}, {size / 2:.0f}, 0], half_size: [{size:.0f}, {size:.0f}, 110], radius: 0, edge: 8}}
  eroded:
    type: volume/erode_noise
    inputs: {{in: based}}
    params: {{amount: 0.15, frequency: 0.015625, octaves: 3, seed: 11}}
  sdf:
    type: volume/sdf
    inputs: {{in: eroded}}
    params: {{method: edt, iso: 0.3, max_distance: 64}}
  anatomy:
    type: volume/cumulus_paint
    inputs: {{sdf: sdf}}
    params: {{base_height: 110}}
  nvdf:
    type: volume/nvdf
    inputs: {{sdf: sdf, detail_type: anatomy.detail_type, density_scale: anatomy.density_scale}}
    params: {{depth: 24, range_min: -64, range_max: 64}}
outputs:
  - {{node: nvdf, port: modeling, file: nvdf/modeling.dds, options: {{encoding: bc6h, quality: fast}}}}
  - {{node: nvdf, port: field_data, file: nvdf/field_data.dds, options: {{encoding: bc4, one_sided: below, range: "0,1"}}}}
""")
PY
echo "world: $size m, ${res}^2 x 64 voxels, $clouds clouds, --tiles $tiles; load before: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/time -v "$atlas" cook "$out/world.yaml" --tiles "$tiles" --no-tile-values --no-cache --quiet --out "$out/cooked" \
  --report "$out/report.json" > "$out/stdout.txt" 2> "$out/time.txt"
/usr/bin/python3 - "$out" <<'PY'
import json, os, re, sys
out = sys.argv[1]
r = json.load(open(os.path.join(out, "report.json")))
t = r["tiles"]
secs = [x["seconds"] for x in t]
cpu = [x["cpu_seconds"] for x in t]
vals = [x["value_bytes_peak"] for x in t]
tile_bytes = sum(f["bytes"] for x in t for f in x["files"])
dds = sum(f["bytes"] for x in t for f in x["files"] if f["path"].endswith(".dds"))
timev = open(os.path.join(out, "time.txt")).read()
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", timev).group(1)) * 1024
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", timev).group(1)
GiB, MiB = 1 << 30, 1 << 20
print(f"tiles: {len(t)} of {r['tiled']['tiles'][0]} x {r['tiled']['tiles'][1]} over {r['tiled']['grid'][0]} x {r['tiled']['grid'][1]} texels")
print(f"per tile: wall {min(secs):.2f} / {sum(secs) / len(secs):.2f} / {max(secs):.2f} s (min / mean / max), "
      f"CPU {sum(cpu) / len(cpu):.2f} s mean, values held at most {max(vals) / MiB:.0f} MiB")
print(f"total: wall {wall} (whole run, {r['seconds']:.1f} s in the cook), CPU {sum(cpu):.1f} s, peak RSS {rss / MiB:.0f} MiB")
print(f"written: {tile_bytes / GiB:.2f} GiB in tile files, of which DDS {dds / MiB:.0f} MiB")
PY
