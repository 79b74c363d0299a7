// atlas/io/image.h - 8/16-bit images (PNG, TGA, ...) through OpenImageIO.
//
// Orientation: y = 0 of a Field2D is the BOTTOM row of the image (world y
// points up, image rows go down), for reading and writing alike; x = 0 is
// the left column. Alpha is never premultiplied (channels are data, not
// colour), on writing or reading. Thread-safe for distinct files.
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

// Writes 1..4 channels (TGA: 1, 3 or 4); the format comes from the
// extension (.png, .tga, or anything else OpenImageIO writes). Values map
// linearly from [range_min, range_max] to 0 .. 2^bits-1, clamped (+-Inf
// included), rounded to nearest. NaN is an error naming the texel and
// channel; so are bits other than 8/16 (TGA: 8) and a range that is not
// finite with max > min. Writes straight to `path`.
void write_image(const Field2D& field, const fs::path& path, const ImageOptions& options = {});

// Any 2D image OpenImageIO reads (first subimage); integer formats become
// 0..1 floats (v / (2^bits-1)), float formats pass through. Channel names are
// the file's, lower-cased ("r", "g", "b", "a"). Bounds default to
// [0, width] x [0, height]. Throws atlas::Error naming the file on a missing,
// unreadable, truncated or volume image, or on invalid bounds.
Field2D read_image(const fs::path& path, std::optional<Box2d> bounds = {}, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
