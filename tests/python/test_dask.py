"""atlas-dask (python/atlas_dask) on a LocalCluster with two worker processes:
the assembled files are byte-identical to one untiled `atlas cook` of the same
graph (the reference is that cook), a failed tile is retried, a worker killed
mid-tile has its tile cooked elsewhere, a tile that keeps failing is named and
leaves no index and no assembled output. Also the CLI's tile flags' errors.

Run by ctest as `dask_driver` (tests/CMakeLists.txt), with ATLAS_BIN and
ATLAS_SOURCE_DIR set; PYTHONPATH holds python/ of the source tree.
"""
import hashlib
import json
import os
import pathlib
import stat
import subprocess
import sys

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(SOURCE_DIR / "python"))
ATLAS = os.environ.get("ATLAS_BIN", "atlas")
WORLD = SOURCE_DIR / "tests" / "graph" / "tiling" / "world.yaml"

distributed = pytest.importorskip("distributed")
import atlas_dask  # noqa: E402


def files_under(d: pathlib.Path):
    return sorted(p.relative_to(d) for p in d.rglob("*")
                  if p.is_file() and ".atlas-outputs.json" not in p.name and ".atlas-staging" not in str(p))


@pytest.fixture(autouse=True)
def worker_tmpdir(tmp_path, monkeypatch):
    # A worker killed mid-tile (the tests below kill some on purpose) cannot remove the
    # temporary directory its tile's report was going to: its spawned processes take
    # TMPDIR from here, so such leftovers stay under pytest's tmp_path, not in /tmp.
    d = tmp_path / "worker-tmp"
    d.mkdir()
    monkeypatch.setenv("TMPDIR", str(d))


@pytest.fixture(scope="module")
def single(tmp_path_factory):
    out = tmp_path_factory.mktemp("single")
    subprocess.run([ATLAS, "cook", str(WORLD), "--out", str(out), "--quiet"], check=True, capture_output=True)
    return out


def assert_same_files(single: pathlib.Path, tiled: pathlib.Path):
    files = files_under(single)
    assert len(files) >= 16
    for f in files:
        assert (tiled / f).exists(), f
        assert (single / f).read_bytes() == (tiled / f).read_bytes(), f"{f} differs from the untiled cook"


def wrapper(tmp_path: pathlib.Path, body: str) -> str:
    """An 'atlas' program that runs `body` (Python) before exec'ing the real one."""
    p = tmp_path / "atlas-wrapper"
    p.write_text(f"""#!{sys.executable}
import os, signal, sys
args = sys.argv[1:]
tile = args[args.index('--tile') + 1] if '--tile' in args else None
marks = {str(tmp_path / 'marks')!r}
os.makedirs(marks, exist_ok=True)
{body}
os.execv({ATLAS!r}, [{ATLAS!r}] + args)
""")
    p.chmod(p.stat().st_mode | stat.S_IXUSR)
    return str(p)


def test_local_cluster_matches_single_cook(single, tmp_path):
    out = tmp_path / "out"
    summary = atlas_dask.run(str(WORLD), (3, 2), "local", str(out), cache=str(tmp_path / "cache"), atlas=ATLAS,
                             workers=2, report=str(tmp_path / "report.json"))
    assert len(summary["tile_results"]) == 6
    assert sorted(tuple(r["tile"]) for r in summary["tile_results"]) == [(i, j) for i in range(3) for j in range(2)]
    assert (out / "tiles" / "index.json").exists()
    assert_same_files(single, out)
    # The index's sha256 of every tile file, against hashlib.
    index = json.loads((out / "tiles" / "index.json").read_text())
    checked = 0
    for o in index["outputs"]:
        assert len(o["tiles"]) == 6
        for t in o["tiles"]:
            for f in t["files"] + [t["raw"]]:
                data = (out / f["path"]).read_bytes()
                assert len(data) == f["bytes"]
                assert hashlib.sha256(data).hexdigest() == f["sha256"], f["path"]
                checked += 1
    assert checked > 6 * 7
    # Each task's result carries atlas's own report of its tile (status, files with hashes).
    for r in summary["tile_results"]:
        assert r["atlas"]["status"] == "cooked" and r["atlas"]["tile"] == r["tile"]
        assert r["atlas"]["value_bytes_peak"] > 0
        assert {f["path"] for f in r["atlas"]["files"]} >= {f"tiles/{r['tile'][0]}_{r['tile'][1]}.json"}
    assert json.loads((tmp_path / "report.json").read_text())["tile_results"][0]["atlas"]["files"]


@pytest.fixture(scope="module")
def cluster():
    # One LocalCluster of two worker processes for the shipped graphs (a start per graph would
    # cost more than most of their tiles).
    from distributed import LocalCluster

    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    yield c.scheduler_address
    c.close()


@pytest.fixture(scope="module")
def quick_tower(tmp_path_factory):
    # The solver's tower at its quick size (tests/cli/cook_shipped_graph.sh): what cumulus_cloudscape
    # and cumulus_side_view read.
    out = tmp_path_factory.mktemp("tower")
    subprocess.run([ATLAS, "cook", str(SOURCE_DIR / "graphs" / "cumulus_growth.yaml"), "--out", str(out), "--quiet", "--no-cache",
                    "--set", "cloud.resolution=[32,32,32]", "--set", "cloud.dx=125"], check=True, capture_output=True)
    return out


# Shipped graphs at reduced sizes: (graph, tiles, --set values); "{tower}" is the quick tower's folder.
SHIPPED = [
    ("graphs/cloudscape.yaml", (3, 2), ("world.resolution=[96,96,32]",)),
    ("graphs/towering_cumulus.yaml", (3, 2), ("density.resolution=[96,96,72]",)),
    ("examples/quickstart.yaml", (3, 2), ()),
    ("graphs/cumulus_cloudscape.yaml", (2, 2), ("tower.file={tower}/cumulus_final.vdb", "world.resolution=[64,64,56]",
                                                "tower_a.resolution=[64,64,56]", "tower_b.resolution=[64,64,56]",
                                                "clouds.resolution=[64,64,56]")),
    ("graphs/cumulus_side_view.yaml", (2, 2), ("frame.file={tower}/cumulus/cloud.0006.vdb",)),
    ("graphs/cumulus_sequence.yaml", (2, 2), ("cloud.resolution=[32,32,32]", "cloud.dx=125")),
    ("graphs/superstorm.yaml", (2, 2), ()),
    ("graphs/superstorm_lifecycle.yaml", (2, 2), ()),
    ("graphs/hzd_weather.yaml", (2, 2), ()),
    ("graphs/envelope_mountain.yaml", (2, 2), ()),
    ("graphs/fc6_forecast.yaml", (2, 2), ()),
    ("graphs/sky_layer.yaml", (2, 2), ()),
    ("graphs/nubis_noise.yaml", (2, 2), ()),
    ("graphs/hzd_noise.yaml", (2, 2), ()),
    ("graphs/cumulus_growth.yaml", (2, 2), ("cloud.resolution=[32,32,32]", "cloud.dx=125")),
    ("graphs/periodic_cumulus_field.yaml", (2, 2), ("cloud.resolution=[32,32,32]", "cloud.dx=125")),
    ("graphs/straka_density_current.yaml", (2, 1), ()),
]


# CI runs one graph of each kind (the voxel cloudscape, two grids, the solver cooked whole, 2D maps
# cooked whole): every graph costs 9 minutes under the sanitizers, and tests/cli/shipped_tiles_test.sh
# compares every shipped graph in-process. ATLAS_DASK_ALL_SHIPPED=1 runs all seventeen.
CI_SHIPPED = {"cloudscape", "quickstart", "cumulus_sequence", "superstorm", "hzd_weather"}
if os.environ.get("ATLAS_DASK_ALL_SHIPPED") != "1":
    SHIPPED = [s for s in SHIPPED if pathlib.Path(s[0]).stem in CI_SHIPPED]


@pytest.mark.parametrize("graph,tiles,sets", SHIPPED, ids=[pathlib.Path(g).stem for g, _, _ in SHIPPED])
def test_shipped_graph_on_a_cluster(graph, tiles, sets, cluster, quick_tower, tmp_path):
    # Every shipped graph that tiles (issue 46 item 2), at a reduced size where it is large: its
    # tiles cooked by two worker processes assemble the untiled cook's bytes, every file.
    extra = tuple(a for s in sets for a in ("--set", s.format(tower=quick_tower)))
    untiled = tmp_path / "untiled"
    subprocess.run([ATLAS, "cook", str(SOURCE_DIR / graph), "--out", str(untiled), "--quiet", "--no-cache", *extra],
                   check=True, capture_output=True)
    out = tmp_path / "out"
    summary = atlas_dask.run(str(SOURCE_DIR / graph), tiles, cluster, str(out), atlas=ATLAS, extra=extra)
    assert len(summary["tile_results"]) == tiles[0] * tiles[1]
    files = files_under(untiled)
    assert files
    for f in files:
        assert (untiled / f).read_bytes() == (out / f).read_bytes(), f"{f} differs from the untiled cook"


def test_failed_tile_is_retried(single, tmp_path):
    # Tile 1,0 fails on its first attempt only.
    atlas = wrapper(tmp_path, """
if tile == '1,0' and not os.path.exists(os.path.join(marks, 'failed')):
    open(os.path.join(marks, 'failed'), 'w').close()
    sys.exit('simulated failure')
""")
    out = tmp_path / "out"
    atlas_dask.run(str(WORLD), (2, 2), "local", str(out), atlas=atlas, workers=2, retries=2)
    assert (tmp_path / "marks" / "failed").exists()
    assert_same_files(single, out)


def process_alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/status") as f:
            return not any(l.startswith("State:") and "Z" in l.split()[1] for l in f)
    except FileNotFoundError:
        return False


def test_worker_killed_mid_tile(single, tmp_path):
    # The first attempt at tile 0,1 kills the worker process that runs it, then goes on as a
    # long tile would: the atlas child must die with its worker (issue 46 item 5), not keep
    # writing while the tile is retried elsewhere.
    atlas = wrapper(tmp_path, """
if tile == '0,1' and not os.path.exists(os.path.join(marks, 'killed')):
    with open(os.path.join(marks, 'killed'), 'w') as f:
        f.write(str(os.getpid()))
    os.kill(os.getppid(), signal.SIGKILL)
    import time
    time.sleep(60)
    sys.exit('worker killed')
""")
    out = tmp_path / "out"
    atlas_dask.run(str(WORLD), (2, 2), "local", str(out), atlas=atlas, workers=2, retries=1)
    child = int((tmp_path / "marks" / "killed").read_text())
    assert not process_alive(child), f"the killed worker's atlas child {child} still runs"
    assert_same_files(single, out)


def test_tile_that_keeps_failing_is_named_and_nothing_is_assembled(tmp_path):
    atlas = wrapper(tmp_path, """
if tile == '1,1':
    sys.exit('simulated failure of tile 1,1')
""")
    out = tmp_path / "out"
    with pytest.raises(atlas_dask.TileError, match=r"tile 1,1: atlas exited with 1 .*simulated failure of tile 1,1"):
        atlas_dask.run(str(WORLD), (2, 2), "local", str(out), atlas=atlas, workers=2, retries=1)
    assert not (out / "tiles" / "index.json").exists()
    assert not (out / "tiles" / "1_1.json").exists()
    assert not (out / "density.exr").exists()
    assert all("1_1" not in str(f) for f in files_under(out))
    # The other tiles are complete, each with its fragment.
    for t in ("0_0", "1_0", "0_1"):
        assert (out / "tiles" / f"{t}.json").exists()


def test_main_reports_errors_with_exit_status(tmp_path, capsys):
    atlas = wrapper(tmp_path, "sys.exit('nope') if tile == '0,0' else None")
    assert atlas_dask.main([str(WORLD), "--tiles", "1,1", "--scheduler", "local", "--out", str(tmp_path / "o"),
                            "--atlas", atlas, "--retries", "0"]) == 1
    assert "tile 0,0" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        atlas_dask.main([str(WORLD), "--tiles", "0,2"])


@pytest.mark.parametrize("args, message", [
    (["--tiles", "3,2", "--tile", "3,0"], "--tile 3,0 is out of range: --tiles 3,2 has tiles 0..2, 0..1"),
    (["--tiles", "5,2"], "does not divide into 5 tiles along x (48 is not a multiple of 5)"),
    (["--tiles", "8,2"], "output 'maps/cover_bc4.dds' is BC-compressed in 4x4 blocks"),
    (["--tiles", "2,2", "--tile", "0,0", "--assemble"], "--assemble needs every tile"),
    (["--tiles", "2"], "--tiles expects two integers"),
    (["--tile", "0,0"], "--tile and --assemble need --tiles"),
])
def test_cli_tile_errors(tmp_path, args, message):
    out = tmp_path / "out"
    r = subprocess.run([ATLAS, "cook", str(WORLD), "--out", str(out), "--quiet", *args], capture_output=True, text=True)
    assert r.returncode != 0
    assert message in r.stderr, r.stderr
    assert not out.exists() or not files_under(out)


def test_cli_refuses_untileable_graph(tmp_path):
    g = tmp_path / "resample.yaml"
    g.write_text("""atlas: 1
nodes:
  a: { type: ndf/noise, params: { resolution: [32, 32] } }
  r: { type: field/resample, inputs: { in: a }, params: { keep_bounds: false, bounds_max: [100, 100, 1] } }
outputs:
  - { node: r, file: r.exr }
""")
    r = subprocess.run([ATLAS, "cook", str(g), "--tiles", "2,2", "--out", str(tmp_path / "o"), "--quiet"], capture_output=True, text=True)
    assert r.returncode != 0
    assert "node 'r' (field/resample) cannot be cooked in tiles: keep_bounds: false" in r.stderr, r.stderr


def test_cli_warns_of_a_halo_wider_than_a_tile(tmp_path):
    # A tileable warp wraps around the world: its halo is the whole map; the cook tiles, and says so.
    g = tmp_path / "warp.yaml"
    g.write_text("""atlas: 1
nodes:
  a: { type: ndf/noise, params: { resolution: [32, 32] } }
  w: { type: ndf/warp, inputs: { in: a, warp: a } }
outputs:
  - { node: w, file: w.exr }
""")
    r = subprocess.run([ATLAS, "cook", str(g), "--tiles", "2,2", "--out", str(tmp_path / "o"), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "warning: " in r.stderr and "node 'w' (ndf/warp): its tiling halo of 32 texels is wider than a tile (16 x 16)" in r.stderr, r.stderr


@pytest.mark.parametrize("entry", [["python/atlas_dask/atlas-dask"], ["-m", "atlas_dask"]])
def test_script_entry_points_with_a_local_cluster(single, tmp_path, entry):
    # The script and `python -m` spawn LocalCluster workers, which import the main module
    # again: without its __main__ guard each worker would start a driver of its own.
    out = tmp_path / "out"
    cmd = [sys.executable, *([str(SOURCE_DIR / entry[0])] if len(entry) == 1 else entry), str(WORLD), "--tiles", "2,2",
           "--scheduler", "local", "--workers", "2", "--out", str(out), "--atlas", ATLAS]
    env = dict(os.environ, PYTHONPATH=str(SOURCE_DIR / "python"))
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=180, env=env)
    assert r.returncode == 0, r.stderr
    assert "[4/4] tile" in r.stderr and "assembled 4 tiles" in r.stderr, r.stderr
    assert_same_files(single, out)


def test_worker_that_keeps_dying_names_the_tile(tmp_path):
    # Every attempt at tile 1,0 kills its worker: the scheduler gives up (allowed-failures 1).
    import dask

    atlas = wrapper(tmp_path, """
if tile == '1,0':
    os.kill(os.getppid(), signal.SIGKILL)
    sys.exit('worker killed')
""")
    out = tmp_path / "out"
    with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
        with pytest.raises(atlas_dask.TileError, match=r"^tile 1,0: KilledWorker"):
            atlas_dask.run(str(WORLD), (2, 1), "local", str(out), atlas=atlas, workers=2, retries=0)
    assert not (out / "tiles" / "index.json").exists()
    assert not (out / "tiles" / "1_0.json").exists()
    assert not (out / "density.exr").exists()


def test_cli_tiled_report(tmp_path):
    # `atlas cook --tiles --report`: every tile with its status, times, memory and
    # files, whose sizes and SHA-256 (hashlib, not atlas) are those on disk.
    out = tmp_path / "out"
    r = subprocess.run([ATLAS, "cook", str(WORLD), "--tiles", "2,2", "--assemble", "--out", str(out), "--quiet",
                        "--report", str(tmp_path / "r.json")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["status"] == "ok" and doc["tiled"]["tiles"] == [2, 2] and doc["tiled"]["grid"] == [48, 32]
    assert [t["tile"] for t in doc["tiles"]] == [[0, 0], [1, 0], [0, 1], [1, 1]]
    assert doc["summary"]["cooked"] == 4 and doc["index"].endswith("tiles/index.json")
    assert len(doc["assembled"]) >= 16
    for t in doc["tiles"]:
        assert t["status"] == "cooked" and t["seconds"] > 0 and t["value_bytes_peak"] > 0
        assert t["rss_peak_bytes"] >= t["value_bytes_peak"]
        for f in t["files"]:
            data = (out / f["path"]).read_bytes()
            assert len(data) == f["bytes"] and hashlib.sha256(data).hexdigest() == f["sha256"], f["path"]

    # Tile 1,0 fails (warp values above 1 on the right of the map, beyond the halo):
    # exit 1, and the report has tile 0,0 cooked and tile 1,0 failed with the reason.
    g = tmp_path / "fails.yaml"
    g.write_text("""atlas: 1
nodes:
  a: { type: ndf/noise, params: { resolution: [64, 16], bounds_max: [6400, 1600] } }
  ramp: { type: ndf/gradient, params: { resolution: [64, 16], bounds_max: [6400, 1600], start: [0, 0], end: [6400, 0] } }
  push: { type: math/remap, inputs: { in: ramp }, params: { out_max: 1.2, clamp: false } }
  w: { type: ndf/warp, inputs: { in: a, warp: push }, params: { amount: 100, tileable: false } }
outputs:
  - { node: w, file: w.exr }
""")
    bad = tmp_path / "bad"
    r = subprocess.run([ATLAS, "cook", str(g), "--tiles", "2,1", "--out", str(bad), "--quiet", "--report", str(tmp_path / "f.json")],
                       capture_output=True, text=True)
    assert r.returncode == 1, r.stderr
    assert "tile 1,0: " in r.stderr and "outside [0, 1]" in r.stderr, r.stderr
    doc = json.loads((tmp_path / "f.json").read_text())
    assert doc["status"] == "failed" and doc["error"]["tile"] == [1, 0]
    assert [(t["tile"], t["status"]) for t in doc["tiles"]] == [([0, 0], "cooked"), ([1, 0], "failed")]
    assert "node 'w' (ndf/warp)" in doc["tiles"][1]["error"] and doc["tiles"][1]["files"] == []
    assert doc["summary"]["failed"] == 1 and "index" not in doc
    assert not (bad / "tiles" / "1_0.json").exists() and (bad / "tiles" / "0_0.json").exists()
