#!/usr/bin/env python3
"""How cost grows (issue 49 item 5): each measured stage at three sizes, with the
exponent of a least-squares fit of log(cost) against log(size). Not a test: it prints
a Markdown table for docs/PERFORMANCE.md. Time only on an otherwise idle machine.

    bench/scaling.py --atlas BUILD/bin/atlas [--base OLD/bin/atlas] [--sizes 128,256,512] [--work DIR]

For each n in --sizes the cloudscape (graphs/cloudscape.yaml, 4 km x 4 km x 512 m) is
cooked on an n x n x n/8 world grid (--set world.resolution; the clouds keep their metres),
every output written but the slice-24 preview, no cache, in a new process:
  cook          the whole `atlas cook` (CPU = user + system, peak RSS)
  noise         the noise erosion node alone (`eroded`, the report's seconds, --jobs 1)
  sdf           the SDF node alone (`sdf`, the report's seconds, --jobs 1)
  bc6h          `atlas compress` of that cook's modeling NVDF EXR, BC6H fast (its encode line)
  bc4           `atlas compress` of that cook's SDF EXR, BC4 normal over [-256, 4096] m
  preview       `atlas preview` of that cook's four-grid VDB, 960x540, --noise none (CPU, RSS)
--base adds the same cook with an older atlas (its CPU and RSS), for before/after in one run.
Size is the voxel count; an exponent of 1 is linear in it.
"""
import argparse
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import tempfile

SOURCE = pathlib.Path(__file__).resolve().parents[1]


def run(cmd):
    """Runs cmd in a new process; returns (stdout+stderr, CPU seconds, peak RSS MB)."""
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env={**os.environ, "ATLAS_CACHE_DIR": ""})
    out = p.stdout.read()
    _, status, ru = os.wait4(p.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed ({os.waitstatus_to_exitcode(status)}): {' '.join(map(str, cmd))}\n{out}")
    return out, ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024


def fit(sizes, costs):
    """Slope of log(cost) against log(size), least squares."""
    xs = [math.log(s) for s in sizes]
    ys = [math.log(max(c, 1e-9)) for c in costs]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--atlas", required=True)
    ap.add_argument("--base", default=None, help="an older atlas: its cook's CPU and RSS beside")
    ap.add_argument("--sizes", default="128,256,512")
    ap.add_argument("--work", default=None)
    a = ap.parse_args()
    sizes = [int(s) for s in a.sizes.split(",")]
    work = pathlib.Path(a.work or tempfile.mkdtemp(prefix="atlas_scaling_"))
    graph = SOURCE / "graphs" / "cloudscape.yaml"
    rows = {}  # stage -> list of (cost, unit)

    def add(stage, value):
        rows.setdefault(stage, []).append(value)

    # Every output but the slice-24 preview (a grid of n/8 < 25 slices has no slice 24).
    outputs = [f for o in ["nvdf/modeling", "nvdf/field_data", "nvdf/cloudscape.vdb", "nvdf/modeling.exr", "nvdf/sdf.exr",
                           "nvdf/modeling.dds", "nvdf/field_data.dds", "preview/density_slices.png", "preview/top_view.png"]
               for f in ("--output", o)]
    voxels = []
    for n in sizes:
        res = f"[{n},{n},{n // 8}]"
        voxels.append(n * n * (n // 8))
        out = work / f"cook_{n}"
        subprocess.run(["rm", "-rf", str(out)], check=True)
        _, cpu, rss = run([a.atlas, "cook", str(graph), "--out", str(out), "--no-cache", "--quiet", "--set", f"world.resolution={res}", *outputs])
        add("cook CPU s", cpu)
        add("cook peak RSS MB", rss)
        if a.base:
            base_out = work / f"base_{n}"
            subprocess.run(["rm", "-rf", str(base_out)], check=True)
            _, bcpu, brss = run([a.base, "cook", str(graph), "--out", str(base_out), "--no-cache", "--quiet", "--set", f"world.resolution={res}", *outputs])
            add("cook CPU s (base)", bcpu)
            add("cook peak RSS MB (base)", brss)
        report = work / f"report_{n}.json"
        run([a.atlas, "cook", str(graph), "--out", str(work / f"one_{n}"), "--no-cache", "--quiet", "--jobs", "1", "--rewrite",
             "--output", "nvdf/sdf.exr", "--set", f"world.resolution={res}", "--report", str(report)])
        nodes = json.loads(report.read_text())["nodes"]
        add("noise erosion node s (1 thread)", nodes["eroded"]["seconds"])
        add("SDF node s (1 thread)", nodes["sdf"]["seconds"])
        text, _, _ = run([a.atlas, "compress", str(out / "nvdf" / "modeling.exr"), "--format", "bc6h", "--quality", "fast", "-o", str(work / "m.dds")])
        add("BC6H fast encode s", float(re.search(r"encode ([0-9.]+) s", text).group(1)))
        text, _, _ = run([a.atlas, "compress", str(out / "nvdf" / "sdf.exr"), "--format", "bc4", "--range", "-256,4096", "-o", str(work / "s.dds")])
        add("BC4 normal encode s", float(re.search(r"encode ([0-9.]+) s", text).group(1)))
        _, cpu, rss = run([a.atlas, "preview", str(out / "nvdf" / "cloudscape.vdb"), "-o", str(work / f"p_{n}.png"), "--noise", "none", "--quiet"])
        add("voxel preview CPU s", cpu)
        add("voxel preview peak RSS MB", rss)

    print(f"# load {open('/proc/loadavg').read().split()[:3]}, {os.cpu_count()} cores; sizes n x n x n/8, n = {a.sizes}")
    print("| stage | " + " | ".join(f"{n}x{n}x{n // 8}" for n in sizes) + " | exponent in voxels |")
    print("|---|" + "---|" * len(sizes) + "---|")
    for stage, values in rows.items():
        print(f"| {stage} | " + " | ".join(f"{v:.3g}" for v in values) + f" | {fit(voxels, values):.2f} |")


if __name__ == "__main__":
    sys.exit(main())
