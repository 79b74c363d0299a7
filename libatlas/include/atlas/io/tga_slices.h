// atlas/io/tga_slices.h - a 3D field as a stack of 32-bit TGA slices, the
// layout of Guerrilla's Nubis voxel cloud pack: DIR/STEM.001.tga ...
// DIR/STEM.NNN.tga (1-based, 3 digits, more only when nz > 999), one per z.
// In each slice x is the column and y the row counted from the BOTTOM (as in
// image.h). Values map from [range_min, range_max] to 0..255.
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

// Returns the files written.
std::vector<fs::path> write_tga_slices(const Field3D& field, const fs::path& dir, const std::string& stem, const SliceOptions& options = {});

// Every slice of the stack that `first_slice` (STEM.001.tga) starts, in order.
// Throws atlas::Error when the name does not follow the pattern or no slice exists.
std::vector<fs::path> find_tga_slices(const fs::path& first_slice);

// Reads the stack as a field with `channels` (1..4) channels, 8-bit values to 0..1.
Field3D read_tga_slices(const fs::path& first_slice, Box3d bounds, int channels = 4, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
