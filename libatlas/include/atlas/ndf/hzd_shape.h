// atlas/ndf/hzd_shape.h - how the HZD noise set's channels make a cloud's base
// shape and detail (GPU Pro 7 ch. 4): one definition for the 2.5D renderer
// (render/layer_model.h) and the engine exports that must match it
// (ndf/three_clouds.h). Header-only, pure.
#pragma once

namespace atlas::ndf {

// Three Worley octaves summed with GPU Pro 7's weights 0.625, 0.25, 0.125.
inline double worley_fbm(double a, double b, double c) { return a * 0.625 + b * 0.25 + c * 0.125; }

// The base shape: the Perlin-Worley `r` dilated by the Worley FBM of g, b, a,
// remap(r, -(1 - fbm), 1, 0, 1), unclamped.
inline double dilated_base(double r, double g, double b, double a) {
    const double low = worley_fbm(g, b, a);
    // Spelled as render::detail::remap_unclamped evaluates it: the same bytes.
    return 0.0 + (r - -(1.0 - low)) / (1.0 - -(1.0 - low)) * (1.0 - 0.0);
}

} // namespace atlas::ndf
