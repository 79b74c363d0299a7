// atlas/io/readers.h - read any field file Atlas knows, by its extension.
#pragma once

#include "atlas/core/memory.h"
#include "atlas/core/value.h"

#include <filesystem>

namespace atlas::io {

// .exr (2D or Atlas 3D), .vdb (all float grids), .png/.tga/.tif/.jpg (2D),
// STEM.001.tga or STEM(0).tga (a TGA slice stack in either naming, 4 channels, bounds [0,n] per axis).
// Returns a Field2DPtr or Field3DPtr; throws atlas::Error naming the file.
Value read_field_file(const std::filesystem::path& path, const MemoryBudget* budget = nullptr);

// A 3D view of a field value: a Field2D becomes a Field3D with one z slice
// (bounds z = [0, 1]); a Field3D is returned as is.
Field3DPtr as_field3d(const Value& v);

} // namespace atlas::io
