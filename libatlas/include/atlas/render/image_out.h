// atlas/render/image_out.h - turning a rendered image into pictures.
//
// The renderer's image (renderer.h) is linear radiance plus transmittance.
// PNG previews are tone-mapped: x * exposure, then Reinhard x / (1 + x)
// per channel, then the sRGB transfer curve; EXR keeps linear floats. The
// files are written by io (io::write_image for the tone-mapped picture,
// io::write_exr with kLinearImageMeaning for the linear one): render works on
// memory. Pure functions; thread-safe.
#pragma once

#include "atlas/core/field.h"

namespace atlas::render {

// Three channels "r", "g", "b" in [0, 1] (display-referred sRGB), same size
// and bounds. exposure > 0 and finite, else atlas::Error.
Field2D tone_map(const Field2D& linear, double exposure = 1.5);

// What the channels of a linear preview EXR hold (its channel_meaning attribute).
inline constexpr const char* kLinearImageMeaning = "linear radiance r, g, b and view transmittance (atlas render)";

} // namespace atlas::render
