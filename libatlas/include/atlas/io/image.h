// atlas/io/image.h - 8/16-bit images (PNG, TGA, ...) through OpenImageIO.
//
// Orientation: y = 0 of a Field2D is the BOTTOM row of the image (world y
// points up, image rows go down), for reading and writing alike.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <filesystem>
#include <optional>

namespace atlas::io {

namespace fs = std::filesystem;

struct ImageOptions {
    int bits = 8;           // 8 or 16 (PNG); TGA is always 8
    float range_min = 0.0f; // value mapped to 0
    float range_max = 1.0f; // value mapped to 2^bits - 1 (values outside are clamped)
};

// Writes 1..4 channels; the format comes from the extension. Values map
// linearly from [range_min, range_max] to the integer range, rounded to
// nearest. NaN is an error naming the texel.
void write_image(const Field2D& field, const fs::path& path, const ImageOptions& options = {});

// Any image OpenImageIO reads; integer formats become 0..1 floats. Bounds
// default to [0, width] x [0, height].
Field2D read_image(const fs::path& path, std::optional<Box2d> bounds = {}, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
