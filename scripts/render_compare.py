#!/usr/bin/python3
"""Luminance error of a preview EXR against a reference EXR (docs/render.md, "Reference: Cycles").

    /usr/bin/python3 scripts/render_compare.py PREVIEW.exr REFERENCE.exr [--threshold T] [--background BG.exr] [--json]

Both images are linear radiance (Atlas's preview EXR: channels r, g, b, transmittance; Cycles: R, G, B).
Luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (Rec. 709 primaries, the linear space of both).
Prints the mean relative error mean(|Y - Yref| / Yref) over the pixels with Yref > threshold x
mean(Yref) (default 0.05), the RMSE of Y, the RMSE relative to mean(Yref), the signed mean ratio
sum(Y) / sum(Yref) - 1 (a brightness bias), and the pixel count used; when PREVIEW has a
transmittance channel, also cloud_* = the same over the pixels where the preview sees cloud
(transmittance < 0.9), which leaves out the sky the two renderers draw identically.
--background BG.exr: REFERENCE is a transparent-film Cycles render (RGBA, premultiplied: the clouds'
own radiance and A = 1 - transmittance) and BG.exr the preview's background (the same preview at
extinction 0): the reference compared is RGB + (1 - A) x BG, the Cycles clouds over Atlas's own
background (the 2.5D mode draws a ground Cycles does not have; docs/render.md, "2.5D against Cycles").
"""
import json
import sys

import numpy as np
import OpenImageIO as oiio


def read_image(path):
    """(the OpenImageIO spec, H x W x C float64 pixels), row 0 at the top."""
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise SystemExit(f"{path}: {oiio.geterror()}")
    spec = inp.spec()
    px = np.asarray(inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT), dtype=np.float64).reshape(spec.height, spec.width, spec.nchannels)
    inp.close()
    return spec, px


def channels(path):
    """{lower-case channel name: H x W float64 array}, row 0 at the top."""
    spec, px = read_image(path)
    return {n.lower(): px[..., i] for i, n in enumerate(spec.channelnames)}


def luminance(path):
    c = channels(path)
    return 0.2126 * c["r"] + 0.7152 * c["g"] + 0.0722 * c["b"]


def composite_luminance(reference, background):
    """Luminance of a premultiplied RGBA reference over a background image."""
    c, b = channels(reference), channels(background)
    if "a" not in c:
        raise SystemExit(f"{reference}: no alpha channel (render it with cycles_reference.py --alpha)")
    y = 0.2126 * c["r"] + 0.7152 * c["g"] + 0.0722 * c["b"]
    yb = 0.2126 * b["r"] + 0.7152 * b["g"] + 0.0722 * b["b"]
    return y + (1 - c["a"]) * yb


def average_images(paths, out):
    """The per-channel mean of same-sized EXRs (independent renders of one scene: a reference of
    their summed samples; linear in premultiplied RGBA, so compositing the mean is the mean of the
    composites), written as a float EXR with the first one's channel names (OpenImageIO)."""
    specs, sums = None, None
    for p in paths:
        spec, px = read_image(p)
        if specs is None:
            specs, sums = spec, px
        elif (spec.width, spec.height, list(spec.channelnames)) != (specs.width, specs.height, list(specs.channelnames)):
            raise SystemExit(f"{p}: size or channels differ from {paths[0]}")
        else:
            sums = sums + px
    spec = oiio.ImageSpec(specs.width, specs.height, specs.nchannels, oiio.FLOAT)
    spec.channelnames = specs.channelnames
    o = oiio.ImageOutput.create(out)
    if o is None or not o.open(out, spec) or not o.write_image((sums / len(paths)).astype(np.float32)) or not o.close():
        raise SystemExit(f"{out}: {oiio.geterror()}")


def cloud_mask(path, max_transmittance=0.9):
    """Pixels where an Atlas preview EXR sees cloud (transmittance below max_transmittance)."""
    return channels(path)["transmittance"] < max_transmittance


def metrics(y, ref, threshold=0.05, cloud=None):
    """Errors of y against ref over pixels with ref > threshold x mean(ref); with a cloud mask,
    also the same errors over the cloud pixels only (keys cloud_*)."""
    if y.shape != ref.shape:
        raise SystemExit(f"image sizes differ: {y.shape} vs {ref.shape}")
    mask = ref > threshold * ref.mean()
    rel = np.abs(y[mask] - ref[mask]) / ref[mask]
    rmse = float(np.sqrt(np.mean((y - ref) ** 2)))
    m = {"mean_rel": float(rel.mean()) if mask.any() else float("nan"), "rmse": rmse, "rmse_rel": rmse / float(ref.mean()),
         "bias": float(y.sum() / ref.sum() - 1), "pixels": int(mask.sum())}
    if cloud is not None:
        cm = mask & cloud
        if cm.any():
            m["cloud_mean_rel"] = float((np.abs(y[cm] - ref[cm]) / ref[cm]).mean())
            m["cloud_rmse"] = float(np.sqrt(np.mean((y[cm] - ref[cm]) ** 2)))
            m["cloud_bias"] = float(y[cm].sum() / ref[cm].sum() - 1)
        m["cloud_pixels"] = int(cm.sum())
    return m


def comparison_rows(rows, out_png, scale=3):
    """A picture of the comparison: per row (preview luminance, reference luminance, cloud mask) the
    preview, the reference (both gamma 2.2 over the reference's 99th percentile) and their ratio on
    the cloud pixels (red: the preview brighter, blue: darker, full colour at a factor of 2; grey off
    the clouds), each pixel scale x scale. Written with OpenImageIO (docs/render.md)."""
    strips = []
    for y, ref, cloud in rows:
        top = max(float(np.percentile(ref, 99)), 1e-12)
        a = np.clip(y / top, 0, 1) ** (1 / 2.2)
        b = np.clip(ref / top, 0, 1) ** (1 / 2.2)
        r = np.where(cloud, np.log2(np.maximum(y, 1e-9) / np.maximum(ref, 1e-9)), 0.0)
        red, blue = np.clip(r, 0, 1), np.clip(-r, 0, 1)
        ratio = np.stack([1 - blue, 1 - red - blue, 1 - red], -1) * np.where(cloud, 1.0, 0.5)[..., None]
        grey = lambda v: np.repeat(v[..., None], 3, -1)
        strips.append(np.concatenate([grey(a), grey(b), np.clip(ratio, 0, 1)], 1))
    img = np.concatenate(strips, 0)
    img = np.repeat(np.repeat(img, scale, 0), scale, 1)
    out = oiio.ImageOutput.create(out_png)
    if out is None:
        raise SystemExit(f"{out_png}: {oiio.geterror()}")
    out.open(out_png, oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.UINT8))
    out.write_image(np.ascontiguousarray((img * 255 + 0.5).astype(np.uint8)))
    out.close()


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    threshold = 0.05
    if "--threshold" in argv:
        threshold = float(argv[argv.index("--threshold") + 1])
        args.remove(argv[argv.index("--threshold") + 1])
    background = None
    if "--background" in argv:
        background = argv[argv.index("--background") + 1]
        args.remove(background)
    if len(args) != 2:
        raise SystemExit(__doc__)
    cloud = cloud_mask(args[0]) if "transmittance" in channels(args[0]) else None
    ref = composite_luminance(args[1], background) if background else luminance(args[1])
    m = metrics(luminance(args[0]), ref, threshold, cloud)
    if "--json" in argv:
        print(json.dumps(m))
    else:
        print(" ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}" for k, v in m.items()))


if __name__ == "__main__":
    main(sys.argv)
