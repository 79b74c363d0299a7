#!/usr/bin/env python3
"""The artist's loop (issue 42): the whole edit, from a parameter change to a new
picture, through one atlas.Session as an editor holds it (Session.preview: values
stay in memory, nothing is written). Not a test: it prints a table for
docs/PERFORMANCE.md with the time and the process's memory beside each step.

    PYTHONPATH=BUILD/python bench/artist_loop.py [--size 960x540] [--proxy 4] [--pixel-size 1] [--atlas BUILD/bin/atlas]

Per graph (graphs/cloudscape.yaml, graphs/superstorm.yaml):
  first picture   a fresh session's first preview at the proxy (includes the
                  built-in noise sets, cooked once per process: the first graph pays)
  edit @proxy     set one parameter, preview again at the proxy (each edit listed)
  cold cook       `atlas cook GRAPH` in a new process, no cache, writing every output
  edit @full      the same edits at full resolution, after one full preview
Targets (issue 42): edit at proxy 4 <= 1 s; edit at full <= 10% of the cold cook;
first picture at proxy 4 <= 5 s. Time only on an otherwise idle machine.
"""
import argparse
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

import atlas

SOURCE = pathlib.Path(__file__).resolve().parents[1]

# (graph, edits): each edit is (node, param, value, what it changes).
CASES = [
    ("graphs/cloudscape.yaml", [
        ("cumulus_c_shape", "seed", 9, "a cloud's billows (early: splat, SDF, NVDF follow)"),
        ("anatomy", "billow_depth", 90, "detail type depth (late: the NVDF follows)"),
        ("eroded", "amount", 0.2, "noise erosion (middle)"),
    ]),
    ("graphs/superstorm.yaml", [
        ("mesocyclone", "radius", 7600, "the tower's radius"),
        ("anvil", "stretch", 2.2, "the anvil's plume"),
        ("set", "type", 0.5, "the cloud type around the storm"),
    ]),
]


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="960x540")
    ap.add_argument("--proxy", type=int, default=4)
    ap.add_argument("--pixel-size", type=int, default=1, help="the preview's pixel_size for the proxy steps (full steps: 1)")
    ap.add_argument("--quality", type=float, default=1.0, help="the preview's quality for the proxy steps (0.5: the 2.5D draft)")
    ap.add_argument("--atlas", default=None, help="the atlas CLI for the cold cook (default: next to the module's build)")
    ap.add_argument("--graphs", nargs="*", default=None)
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.split("x"))
    opts = {"size": (w, h)}
    proxy_opts = {"size": (w, h), "pixel_size": a.pixel_size, "quality": a.quality}
    cli = a.atlas or str(pathlib.Path(atlas.__file__).resolve().parents[2] / "bin" / "atlas")
    print(f"# load {open('/proc/loadavg').read().split()[:3]}, {os.cpu_count()} cores, {a.size}, proxy {a.proxy}, pixel size {a.pixel_size} and quality {a.quality} at the proxy")
    print("graph | step | seconds | RSS MB | peak MB")
    print("---|---|---|---|---")
    for graph, edits in CASES:
        if a.graphs and graph not in a.graphs:
            continue
        path = SOURCE / graph
        s = atlas.Session()
        s.load(path)
        name = pathlib.Path(graph).name
        row = lambda step, sec: print(f"{name} | {step} | {sec:.2f} | {rss_mb():.0f} | {peak_mb():.0f}", flush=True)
        row(f"first picture @proxy {a.proxy}", timed(lambda: s.preview(proxy_opts, proxy=a.proxy)))
        for node, param, value, what in edits:
            s.set(node, param, value)
            row(f"edit @proxy {a.proxy}: {node}.{param} ({what})", timed(lambda: s.preview(proxy_opts, proxy=a.proxy)))
        with tempfile.TemporaryDirectory() as out:
            t = time.perf_counter()
            subprocess.run([cli, "cook", str(path), "--out", out, "--no-cache", "--quiet"], check=True, stdout=subprocess.DEVNULL,
                           env={**os.environ, "ATLAS_CACHE_DIR": ""})
            cold = time.perf_counter() - t
        row("cold cook (atlas cook, every output written, new process)", cold)
        s2 = atlas.Session()
        s2.load(path)
        row("first picture @full", timed(lambda: s2.preview(opts)))
        for node, param, value, what in edits:
            s2.set(node, param, value)
            sec = timed(lambda: s2.preview(opts))
            row(f"edit @full: {node}.{param} ({100 * sec / cold:.0f}% of the cold cook)", sec)
        del s, s2


if __name__ == "__main__":
    sys.exit(main())
