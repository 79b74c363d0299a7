// atlas/io/tga_slices.h - a 3D field as a stack of 32-bit TGA slices, the
// layout of Guerrilla's Nubis voxel cloud pack: DIR/STEM.001.tga ...
// DIR/STEM.NNN.tga (1-based, 3 digits, more only when nz > 999), one per z.
// In each slice x is the column and y the row counted from the BOTTOM (as in
// image.h), z the slice index minus one. Each file is an uncompressed 32-bit
// BGRA TGA (8 alpha bits, unassociated). Values map linearly from
// [range_min, range_max] to 0..255, clamped, rounded to nearest.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace atlas::io {

namespace fs = std::filesystem;

struct SliceOptions {
    float range_min = 0.0f, range_max = 1.0f;
    uint8_t default_alpha = 255;
    // Field channel for R, G, B, A; -1 fills (0 for RGB, default_alpha for A).
    // Empty: channels 0..3 as available.
    std::vector<int> channel_map;
};

// Writes DIR/STEM.001.tga ... (DIR must exist) and returns the files written,
// in z order. NaN is an error naming the slice file and voxel.
std::vector<fs::path> write_tga_slices(const Field3D& field, const fs::path& dir, const std::string& stem, const SliceOptions& options = {});

// Every slice of a stack, in z order. `first_slice` names the stack as its
// first slice (STEM.001.tga, any zero padding), a pattern (STEM.###.tga,
// STEM.%03d.tga, STEM.*.tga) or DIR/STEM. All STEM.<n>.tga in the directory
// count; they must be exactly 1..N. Throws atlas::Error naming the missing
// slice on a gap, and naming the file when none exists.
std::vector<fs::path> find_tga_slices(const fs::path& first_slice);

// Reads the stack as a field with `channels` (1..4) channels (R, G, B, A),
// 8-bit values to 0..1 (v / 255); channels a slice lacks read as 0 (alpha 1).
// Every slice must have the first one's size (the error names the file).
Field3D read_tga_slices(const fs::path& first_slice, Box3d bounds, int channels = 4, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
