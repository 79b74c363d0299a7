// atlas/render/image_out.h - turning a rendered image into files.
//
// The renderer's image (renderer.h) is linear radiance plus transmittance.
// PNG previews are tone-mapped: x * exposure, then Reinhard x / (1 + x)
// per channel, then the sRGB transfer curve; EXR keeps linear floats.
// Pure functions; thread-safe for distinct files.
#pragma once

#include "atlas/core/field.h"

#include <filesystem>

namespace atlas::render {

// Three channels "r", "g", "b" in [0, 1] (display-referred sRGB), same size
// and bounds. exposure > 0 and finite, else atlas::Error.
Field2D tone_map(const Field2D& linear, double exposure = 1.5);

// Writes tone_map(image) as an 8-bit PNG (or any io::write_image format).
void write_preview_png(const Field2D& image, const std::filesystem::path& path, double exposure = 1.5);
// Writes the linear channels r, g, b, transmittance as 32-bit float EXR.
void write_preview_exr(const Field2D& image, const std::filesystem::path& path);

} // namespace atlas::render
