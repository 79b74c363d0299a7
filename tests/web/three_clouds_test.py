#!/usr/bin/env python3
"""Issue 44, item 4: a real-time renderer no one here wrote draws Atlas's 2.5D exports.

`atlas view GRAPH` writes the NDF set in @takram/three-clouds' layout and a page
(plugins/web) that three.js + three-clouds render; headless Chromium draws it in
software WebGL2 (plugins/web/render_page.py). The same NDF set and camera go
through `atlas preview`. Compared, as opacity (three-clouds' clouds buffer alpha,
Atlas's 1 - transmittance) on 320 x 180 pictures:

- coverage pattern: graphs/hzd_weather.yaml seen from 30 km straight down. Pearson
  correlation of the opacity maps, raw and box-filtered over 11 px (about 2 km at
  the clouds): the weather map's pattern and the erosion noise (the same volume:
  shape.bin is Atlas's equalised base noise) must line up. A negative control
  (Atlas's picture mirrored) must not.
- layer heights: tests/web/two_clouds.yaml, a stratus and a cumulus column 25 km
  away, seen level from 2750 m. The rows where each column's silhouette
  (opacity > 0.5) begins and ends must agree within 2 px (100 m at 25 km).

Exit 77 (skipped) without Chromium or the built page, unless CI is set: CI installs
both (scripts/setup.sh, scripts/web.sh) and must run this.
"""
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

SRC = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
ATLAS = os.environ.get("ATLAS", str(SRC / "build" / "bin" / "atlas"))
sys.path.insert(0, str(SRC / "plugins" / "web"))
import render_page  # noqa: E402

SIZE = (320, 180)
EARTH = "6378137"  # three-clouds' WGS84 equator, where atlas view places the scene


def skip_or_fail(why):
    if os.environ.get("CI"):
        print(f"FAIL: {why}", file=sys.stderr)
        sys.exit(1)
    print(f"SKIP: {why}", file=sys.stderr)
    sys.exit(77)


def pixels(path):
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise RuntimeError(f"{path}: {buf.geterror()}")
    return buf.get_pixels(oiio.FLOAT)


def both(work, name, graph, camera, fov):
    """Three-clouds' opacity and Atlas's for one graph and camera."""
    page = work / name
    subprocess.run([ATLAS, "view", str(graph), "-o", str(page), "--no-open", "--quiet", "--no-cache", "--camera", camera,
                    "--fov", str(fov)], check=True)
    three = work / f"{name}_three_alpha.png"
    seconds = render_page.render(page / "index.html", three, f"still=1&frames=3&size={SIZE[0]}x{SIZE[1]}&output=alpha", 400)
    print(f"{name}: three-clouds rendered in {seconds:.1f} s")
    atlas = work / f"{name}_atlas.exr"
    subprocess.run([ATLAS, "preview", str(graph), "-o", str(atlas), "--size", f"{SIZE[0]}x{SIZE[1]}", "--camera", camera, "--fov",
                    str(fov), "--earth-radius", EARTH, "--quiet", "--no-cache"], check=True)
    t = pixels(three)[:, :, 0]
    a = 1.0 - pixels(atlas)[:, :, 3]
    assert t.shape == a.shape == (SIZE[1], SIZE[0]), (t.shape, a.shape)
    assert np.isfinite(t).all() and np.isfinite(a).all()
    return t, a


def box(x, r):
    k = np.ones(2 * r + 1) / (2 * r + 1)
    x = np.apply_along_axis(lambda v: np.convolve(np.pad(v, r, mode="edge"), k, "valid"), 0, x)
    return np.apply_along_axis(lambda v: np.convolve(np.pad(v, r, mode="edge"), k, "valid"), 1, x)


def corr(a, b):
    return float(np.corrcoef(a.ravel(), b.ravel())[0, 1])


def silhouette_rows(alpha, cols):
    rows = np.where((alpha[:, cols] > 0.5).any(axis=1))[0]
    return (int(rows.min()), int(rows.max())) if len(rows) else None


def main():
    chromium = os.environ.get("CHROMIUM") or shutil.which("chromium")
    if not chromium:
        skip_or_fail("chromium is not installed (scripts/setup.sh installs it)")
    if not (SRC / "plugins/web/dist/atlas_view.js").is_file() and not os.environ.get("ATLAS_WEB_DIR"):
        skip_or_fail("the page is not built (scripts/web.sh)")
    failures = []
    with tempfile.TemporaryDirectory(prefix="atlas-web-") as tmp:
        work = pathlib.Path(tmp)

        # Bad input: clear messages, nothing written.
        for env, graph, expect in (({"ATLAS_WEB_DIR": str(work / "nowhere")}, "graphs/hzd_weather.yaml", "scripts/web.sh"),
                                   ({}, "graphs/nubis_noise.yaml", "no NDF set")):
            r = subprocess.run([ATLAS, "view", str(SRC / graph), "-o", str(work / "refused"), "--no-open", "--quiet"],
                               env={**os.environ, **env}, capture_output=True, text=True)
            if r.returncode != 1 or expect not in r.stderr or (work / "refused").exists():
                failures.append(f"atlas view {graph} {env}: expected status 1 saying '{expect}', nothing written; got {r.returncode}: {r.stderr.strip()}")

        # Coverage pattern, from above.
        t, a = both(work, "top", SRC / "graphs/hzd_weather.yaml", "30000,29990,30000,30000,30000,0", 60)
        raw, smooth = corr(t, a), corr(box(t, 5), box(a, 5))
        mirrored = corr(box(t, 5), box(a[:, ::-1], 5))
        frac_t, frac_a = float((t > 0.5).mean()), float((a > 0.5).mean())
        print(f"coverage pattern: correlation {raw:.3f} raw, {smooth:.3f} over 11 px; mirrored control {mirrored:.3f}; "
              f"cloud fraction three-clouds {frac_t:.3f}, Atlas {frac_a:.3f}")
        if raw < 0.6:
            failures.append(f"raw opacity correlation {raw:.3f} < 0.6")
        if smooth < 0.85:
            failures.append(f"filtered opacity correlation {smooth:.3f} < 0.85")
        if mirrored > 0.5:
            failures.append(f"the mirrored control correlates {mirrored:.3f} > 0.5: the measure does not tell patterns apart")
        if abs(frac_t - frac_a) > 0.15:
            failures.append(f"cloud fractions differ by {abs(frac_t - frac_a):.3f} > 0.15")

        # Layer heights, from the side: the west column (stratus) is in columns
        # 0..99, the east one (cumulus) in 220..319.
        t, a = both(work, "side", SRC / "tests/web/two_clouds.yaml", "100000,75000,2750,100000,100000,2750", 20)
        metres_per_px = 25000 * np.tan(np.radians(10)) / (SIZE[1] / 2)
        for name, cols in (("stratus", slice(0, 100)), ("cumulus", slice(220, 320))):
            rt, ra = silhouette_rows(t, cols), silhouette_rows(a, cols)
            print(f"{name}: silhouette rows three-clouds {rt}, Atlas {ra} ({metres_per_px:.0f} m per row at 25 km)")
            if rt is None or ra is None:
                failures.append(f"{name}: no silhouette (three-clouds {rt}, Atlas {ra})")
                continue
            for what, i in (("top", 0), ("base", 1)):
                if abs(rt[i] - ra[i]) > 2:
                    failures.append(f"{name} {what}: rows {rt[i]} vs {ra[i]} differ by more than 2 px")
        if silhouette_rows(t, slice(0, 100)) == silhouette_rows(t, slice(220, 320)):
            failures.append("the stratus and cumulus silhouettes are the same height: the layers are not told apart")
    for f in failures:
        print(f"FAIL: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
