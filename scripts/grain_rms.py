#!/usr/bin/env python3
"""Grain of a render against a reference with many more samples (issue 41 item 6): RMS in
/255 over the cloud region, the pixels where either picture differs from its row's median
by more than 6/255 (sky and ground are nearly constant along a row, clouds are not). Both
pictures are read with OpenImageIO and rounded to 8 bits.

    grain_rms.py RENDER REFERENCE      prints "RMS REGION_PERCENT"

Used by bench/grain.sh and tests/look/test_grain.py."""
import sys

import numpy as np
import OpenImageIO as oiio


def read(path):
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise RuntimeError(f"{path}: {buf.geterror()}")
    return np.round(buf.get_pixels(oiio.FLOAT)[..., :3] * 255.0)


def cloud_region(img):
    return np.abs(img - np.median(img, axis=1, keepdims=True)).max(axis=2) > 6


def grain(render_path, reference_path):
    """(RMS /255 over the cloud region, the region's share of the frame in %)."""
    a, b = read(render_path), read(reference_path)
    if a.shape != b.shape:
        raise ValueError(f"{render_path} is {a.shape[1]}x{a.shape[0]}, {reference_path} is {b.shape[1]}x{b.shape[0]}")
    m = cloud_region(a) | cloud_region(b)
    d = (a - b)[m]
    return (float(np.sqrt((d ** 2).mean())) if d.size else 0.0), 100.0 * float(m.mean())


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rms, region = grain(sys.argv[1], sys.argv[2])
    print(f"{rms:.2f} {region:.1f}")
