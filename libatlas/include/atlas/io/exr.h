// atlas/io/exr.h - OpenEXR files (through OpenEXR itself).
//
// 2D fields are one image (row 0 of the file is the field's top row, y max).
// 3D fields are stored as one image nx wide and ny*nz tall: slice z occupies
// file rows [z*ny, (z+1)*ny), each slice top row first. Header attributes
// carry what an image cannot: atlas:bounds_min / atlas:bounds_max (V2d or
// V3d, metres), atlas:voxel_size, atlas:resolution (V3i, 3D only),
// atlas:channel_meaning (string) and atlas:version (int).
// Float files round-trip bit for bit. Thread-safe (no shared state).
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/value.h"

#include <filesystem>
#include <string>

namespace atlas::io {

namespace fs = std::filesystem;

struct ExrOptions {
    bool half = false;           // store 16-bit half floats (lossy: ~3 significant digits)
    std::string channel_meaning; // free text stored in atlas:channel_meaning
};

void write_exr(const Field2D& field, const fs::path& path, const ExrOptions& options = {});
void write_exr(const Field3D& field, const fs::path& path, const ExrOptions& options = {});

// A Field2DPtr or Field3DPtr (3D when the header has atlas:resolution). A
// plain EXR reads as a 2D field over [0, width] x [0, height]. Channels keep
// their file names, in the file's (alphabetical) order. Throws atlas::Error
// naming the file on anything unreadable.
Value read_exr(const fs::path& path, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
