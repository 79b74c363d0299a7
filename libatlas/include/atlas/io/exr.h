// atlas/io/exr.h - OpenEXR files (through OpenEXR itself).
//
// 2D fields are one image (row 0 of the file is the field's top row, y max).
// 3D fields are stored as one image nx wide and ny*nz tall: slice z occupies
// file rows [z*ny, (z+1)*ny), each slice top row first. Header attributes
// carry what an image cannot: atlas:bounds_min / atlas:bounds_max (V2d or
// V3d, metres), atlas:voxel_size, atlas:resolution (V3i, 3D only),
// atlas:channel_meaning (string) and atlas:version (int).
// atlas:channels (string vector) keeps the field's channel order, which EXR
// itself does not (it sorts channels by name).
// Float files round-trip bit for bit (NaN, Inf, denormals, -0 included).
// Compression ZIP, one writer thread: same field, same bytes.
// Thread-safe (no shared state); distinct paths may be written concurrently.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/value.h"

#include <filesystem>
#include <string>

namespace atlas::io {

namespace fs = std::filesystem;

struct ExrOptions {
    // Store 16-bit half floats: 11 significant bits (relative error <= 2^-11,
    // round to nearest even). A finite value beyond +-65504 is an error
    // rather than a silent infinity.
    bool half = false;
    std::string channel_meaning; // free text stored in atlas:channel_meaning
    // ZIP (the default) or none: float data that does not compress (a signed
    // distance field's mantissas) is written in a fraction of the time and
    // barely larger uncompressed.
    bool compress = true;
};

// Writes straight to `path` (atomicity is the caller's: core/files.h).
// Throws atlas::Error naming the file on duplicate/empty channel names, half
// overflow, or an I/O failure.
void write_exr(const Field2D& field, const fs::path& path, const ExrOptions& options = {});
void write_exr(const Field3D& field, const fs::path& path, const ExrOptions& options = {});

// A Field2DPtr or Field3DPtr (3D when the header has atlas:resolution). A
// plain EXR reads as a 2D field over [0, width] x [0, height] (any data
// window; half and uint channels convert to float). Channels keep their file
// names, in atlas:channels order when present, else in conventional order:
// layers ("diffuse.R") in the file's order, within a layer R, G, B, A, then X,
// Y, Z (a lone luminance Y before its A), then other names alphabetically (so
// an RGB file from another tool is R, G, B, not OpenEXR's listing B, G, R).
// Only the first part of a multi-part file is read; deep, subsampled and
// luminance/chroma (RY, BY) images are refused. Allocations are checked
// against `budget` (default: MemoryBudget's default limit), so a corrupt
// header cannot exhaust memory. Throws atlas::Error naming the file on
// anything unreadable (missing, not EXR, truncated, size mismatch).
Value read_exr(const fs::path& path, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
