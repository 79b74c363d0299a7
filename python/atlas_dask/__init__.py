"""atlas-dask: cook an Atlas graph in XY tiles on a Dask ``distributed`` cluster.

    atlas-dask GRAPH --tiles NX,NY --scheduler ADDRESS|local [--cache DIR] [--out DIR]

Every tile is one task, ``atlas cook GRAPH --tiles NX,NY --tile I,J --out OUT``
run by the ``atlas`` program on a worker (a crash in a tile cannot take the
worker's Python down with it, and a tile's files are committed all together
or not at all). A failed tile is retried (``--retries``); a worker that dies
mid-tile has its task rescheduled by the scheduler. When every tile is done
the driver runs ``atlas cook GRAPH --tiles NX,NY [--assemble]`` itself, which
finds every tile current, writes OUT/tiles/index.json and (unless
``--no-assemble``) the untiled outputs, byte for byte what one cook writes.

OUT (and --cache, when given) must be directories every worker and the
driver see at the same path: a shared file system on a real cluster. The
workers need the ``atlas`` program (``--atlas``, default $ATLAS_BIN or the
one on PATH) and Dask; this module travels with the tasks (cloudpickle by
value), so it need not be installed on them. docs/scale.md has the details.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

__all__ = ["cook_tile", "run", "main"]


class TileError(RuntimeError):
    """A tile's cook failed (the message names the tile and carries atlas's error)."""


def _pair(text: str, what: str, minimum: int) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} expects two integers as X,Y, got '{text}'") from None
    if a < minimum or b < minimum:
        raise argparse.ArgumentTypeError(f"{what} expects two integers >= {minimum}, got '{text}'")
    return a, b


def _dies_with_this_process():
    """A preexec function: the child gets SIGKILL when the process that started it dies (Linux's
    PR_SET_PDEATHSIG), so a worker killed mid-tile takes its atlas with it instead of leaving it
    writing while the tile is retried elsewhere. Resolved before the fork: the child only calls."""
    if not sys.platform.startswith("linux"):
        return None
    import ctypes
    import signal

    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    parent = os.getpid()

    def preexec():
        prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # the parent died before the line above
            os._exit(1)
    return preexec


def _run_atlas(cmd: list[str]) -> tuple[int, str, str, float, int]:
    """Runs atlas; returns (exit code, stdout, stderr, seconds, peak RSS in bytes of that process)."""
    t0 = time.monotonic()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, stdin=subprocess.DEVNULL, preexec_fn=_dies_with_this_process())
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return (proc.returncode, out.read().decode(errors="replace"), err.read().decode(errors="replace"),
                time.monotonic() - t0, int(usage.ru_maxrss) * 1024)


def cook_tile(atlas: str, graph: str, tiles: tuple[int, int], tile: tuple[int, int], out: str,
              cache: str | None = None, extra: tuple[str, ...] = ()) -> dict:
    """Cooks one tile with the atlas CLI (the Dask task). Raises TileError on failure."""
    cmd = [atlas, "cook", graph, "--tiles", f"{tiles[0]},{tiles[1]}", "--tile", f"{tile[0]},{tile[1]}",
           "--out", out, "--quiet", *extra]
    if cache:
        cmd += ["--cache", cache]
    # atlas's own report of the tile (docs/report.md, "Tiled cooks"): its files with
    # hashes, CPU time and the values it held, for the driver's --report.
    with tempfile.TemporaryDirectory(prefix="atlas-dask-") as tmp:
        report = os.path.join(tmp, "tile.json")
        code, stdout, stderr, seconds, rss = _run_atlas(cmd + ["--report", report])
        try:
            with open(report, encoding="utf-8") as f:
                tile_report = json.load(f)["tiles"][0]
        except (OSError, ValueError, KeyError, IndexError):
            tile_report = None
    if code != 0:
        raise TileError(f"tile {tile[0]},{tile[1]}: atlas exited with {code} on {socket.gethostname()}: "
                        f"{stderr.strip() or stdout.strip()}")
    return {"tile": list(tile), "seconds": seconds, "peak_rss_bytes": rss, "host": socket.gethostname(),
            "pid": os.getpid(), "files": [l for l in stdout.splitlines()[1:] if l], "atlas": tile_report}


def _client(scheduler: str, workers: int):
    from distributed import Client, LocalCluster

    if scheduler == "local":
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        return Client(cluster), cluster
    return Client(scheduler), None


def _ship_by_value():
    # Workers need not have this module installed: its functions travel by value.
    try:
        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[__name__])
    except (ImportError, AttributeError, ValueError):
        pass


def run(graph: str, tiles: tuple[int, int], scheduler: str = "local", out: str = ".", cache: str | None = None,
        atlas: str | None = None, workers: int = 2, retries: int = 2, assemble: bool = True,
        extra: tuple[str, ...] = (), log=sys.stderr, report: str | None = None) -> dict:
    """Cooks every tile on the cluster, then writes the tile index (and assembles). Returns a summary.

    Raises TileError naming the tile when one still fails after `retries` retries; then
    no index and no assembled output are written (the tiles that finished stay, complete).
    """
    atlas = atlas or os.environ.get("ATLAS_BIN") or shutil.which("atlas")
    if not atlas:
        raise TileError("no atlas program: pass --atlas PATH or set ATLAS_BIN")
    atlas = os.path.abspath(atlas) if os.path.exists(atlas) else atlas
    graph, out = os.path.abspath(graph), os.path.abspath(out)
    cache = os.path.abspath(cache) if cache else None
    os.makedirs(out, exist_ok=True)
    _ship_by_value()
    from distributed import as_completed

    t0 = time.monotonic()
    client, cluster = _client(scheduler, workers)
    results = []
    try:
        nx, ny = tiles
        futures = {}
        for j in range(ny):
            for i in range(nx):
                f = client.submit(cook_tile, atlas, graph, (nx, ny), (i, j), out, cache, tuple(extra),
                                  key=f"atlas-tile-{i}-{j}-{os.getpid()}-{time.time_ns()}", pure=False, retries=retries)
                futures[f] = (i, j)
        total = len(futures)
        failure = None
        for k, f in enumerate(as_completed(list(futures)), 1):
            i, j = futures[f]
            try:
                r = f.result()
            except Exception as e:  # the tile failed after its retries, or its worker kept dying
                if failure is None:
                    failure = e if isinstance(e, TileError) else TileError(f"tile {i},{j}: {type(e).__name__}: {e}")
                print(f"[{k}/{total}] tile {i},{j} FAILED: {e}", file=log, flush=True)
                continue
            results.append(r)
            print(f"[{k}/{total}] tile {i},{j} done on {r['host']} pid {r['pid']} in {r['seconds']:.2f} s, "
                  f"peak {r['peak_rss_bytes'] / 2**20:.0f} MiB", file=log, flush=True)
        if failure is not None:
            raise failure
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    cluster_seconds = time.monotonic() - t0

    # Every tile is on disk: the index (and the untiled outputs), written here.
    cmd = [atlas, "cook", graph, "--tiles", f"{tiles[0]},{tiles[1]}", "--out", out, "--quiet", *extra]
    if assemble:
        cmd.append("--assemble")
    code, stdout, stderr, seconds, rss = _run_atlas(cmd)
    if code != 0:
        raise TileError(f"writing the tile index{' and assembling' if assemble else ''} failed: {stderr.strip()}")
    print(f"{'assembled' if assemble else 'indexed'} {total} tiles in {seconds:.2f} s "
          f"({cluster_seconds:.2f} s on the cluster): {os.path.join(out, 'tiles', 'index.json')}", file=log, flush=True)
    summary = {"graph": graph, "tiles": list(tiles), "out": out, "cluster_seconds": cluster_seconds,
               "final_seconds": seconds, "final_peak_rss_bytes": rss,
               "tile_results": sorted(results, key=lambda r: (r["tile"][1], r["tile"][0])),
               "index": os.path.join(out, "tiles", "index.json")}
    if report:
        with open(report, "w") as fh:
            json.dump(summary, fh, indent=2)
    return summary


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="atlas-dask", description="Cook an Atlas graph in XY tiles on a Dask cluster (docs/scale.md).")
    p.add_argument("graph", help="the graph file (a path every worker sees)")
    p.add_argument("--tiles", required=True, type=lambda s: _pair(s, "--tiles", 1), help="NX,NY tiles of the XY grid")
    p.add_argument("--scheduler", default="local", help="scheduler address (tcp://host:8786), or 'local' for a LocalCluster")
    p.add_argument("--workers", type=int, default=2, help="with --scheduler local: worker processes (default 2)")
    p.add_argument("--out", default=".", help="output directory every worker sees (default .)")
    p.add_argument("--cache", help="on-disk cache directory the workers share (atlas cook --cache)")
    p.add_argument("--atlas", help="the atlas program on the workers (default $ATLAS_BIN or atlas on PATH)")
    p.add_argument("--retries", type=int, default=2, help="retries of a failed tile (default 2)")
    p.add_argument("--no-assemble", action="store_true", help="write the tile index only, not the untiled outputs")
    p.add_argument("--no-tile-values", action="store_true",
                   help="tiles keep only their files, not an exact copy of their values (implies --no-assemble)")
    p.add_argument("--set", action="append", default=[], metavar="NODE.PARAM=VALUE", help="parameter override; repeatable")
    p.add_argument("--memory-budget", help="per-tile memory budget (atlas cook --memory-budget)")
    p.add_argument("--jobs", help="threads per tile (atlas cook --jobs)")
    p.add_argument("--report", help="write a JSON summary: per-tile seconds, peak RSS, host")
    a = p.parse_args(argv)
    extra = []
    for kv in a.set:
        extra += ["--set", kv]
    if a.memory_budget:
        extra += ["--memory-budget", a.memory_budget]
    if a.jobs:
        extra += ["--jobs", a.jobs]
    if a.no_tile_values:
        extra += ["--no-tile-values"]
    try:
        run(a.graph, a.tiles, a.scheduler, a.out, a.cache, a.atlas, a.workers, a.retries, not (a.no_assemble or a.no_tile_values),
            tuple(extra), report=a.report)
    except TileError as e:
        print(f"atlas-dask: error: {e}", file=sys.stderr)
        return 1
    return 0
