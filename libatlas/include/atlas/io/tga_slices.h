// atlas/io/tga_slices.h - a 3D field as a stack of TGA slices, the layout of
// Guerrilla's Nubis voxel cloud pack, one file per z slice, in one of two
// namings (SliceNaming):
//   atlas  DIR/STEM.001.tga ... DIR/STEM.NNN.tga (1-based, 3 digits, more
//          only when nz > 999)
//   nubis  DIR/STEM(0).tga ... DIR/STEM(N-1).tga (0-based, no padding; the
//          pack's own files, e.g. modeling_data(0).tga ... (63))
// In each slice x is the column and y the row counted from the BOTTOM (as in
// image.h), z the slice's position in the stack. Each file is a true-colour
// TGA, by default 32-bit BGRA (8 alpha bits, unassociated), run-length
// encoded (image type 10, what the pack uses) or uncompressed (type 2);
// 24-bit BGR and 8-bit grey (types 3 / 11) on request. Values map linearly
// from [range_min, range_max] to 0..255, clamped, rounded to nearest.
// Readers and writers here never go through an image library: the pack's
// modeling slices carry A = 0, which premultiplying readers turn into black.
// Thread-safe (no shared state); deterministic (same field, same bytes).
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace atlas::io {

namespace fs = std::filesystem;

enum class SliceNaming { atlas, nubis };

// Pixel layout of each written slice.
enum class SlicePixels {
    rgba, // 32 bits, B G R A bytes, 8 alpha bits
    rgb,  // 24 bits, B G R bytes
    gray  // 8 bits, the R channel only (image type 3 / 11)
};

struct SliceOptions {
    float range_min = 0.0f, range_max = 1.0f;
    uint8_t default_alpha = 255;
    // Field channel for R, G, B, A; -1 fills (0 for RGB, default_alpha for A).
    // Empty: channels 0..3 as available. Entries beyond what `pixels` holds
    // (G, B, A for gray; A for rgb) are ignored.
    std::vector<int> channel_map;
    SliceNaming naming = SliceNaming::atlas;
    SlicePixels pixels = SlicePixels::rgba;
    // Run-length encoding (TGA image types 10 / 11). Packets never span two
    // rows (TGA 2.0), runs need >= 2 equal pixels (>= 3 for 8-bit grey).
    bool rle = true;
};

// One decoded TGA image: 8-bit samples, `channels` per pixel (1 grey, 3 RGB
// or 4 RGBA, in that order; BGR byte order undone), row 0 the BOTTOM row.
struct TgaImage {
    int width = 0, height = 0, channels = 0;
    std::vector<uint8_t> pixels; // width * height * channels
};

// Reads an uncompressed or RLE true-colour or grey TGA (image types 2, 3, 10,
// 11; 8-bit grey, 15/16, 24 or 32 bits per pixel; either origin). RLE packets
// may span rows. Throws atlas::Error naming the file on anything else:
// colour-mapped images, a truncated header or pixel data, an RLE packet that
// runs past the end of the image (with the byte offset), a size above the
// memory budget (checked before allocating).
TgaImage read_tga(const fs::path& file, const MemoryBudget* budget = nullptr);

// Writes one TGA (origin bottom-left, TGA 2.0 footer) straight to `file`:
// channels 4 -> 32-bit BGRA, 3 -> 24-bit BGR, 1 -> 8-bit grey; RLE or not.
// Throws atlas::Error naming the file when it cannot be written.
void write_tga(const fs::path& file, const TgaImage& image, bool rle);

// The name of slice `z` (0-based) in a stack of `nz` slices.
std::string tga_slice_name(const std::string& stem, int z, int nz, SliceNaming naming);

// Writes the stack into DIR (which must exist) and returns the files written,
// in z order. All slices are staged and moved into place together: a failure
// (NaN, a full disk) leaves no slice behind. NaN is an error naming the slice
// file and voxel.
std::vector<fs::path> write_tga_slices(const Field3D& field, const fs::path& dir, const std::string& stem, const SliceOptions& options = {});

// Every slice of a stack, in z order. `first_slice` names the stack as its
// first slice (STEM.001.tga with any zero padding, or STEM(0).tga), a pattern
// (STEM.###.tga, STEM.%03d.tga, STEM.*.tga, STEM(*).tga, STEM(%d).tga) or
// DIR/STEM (either naming; both present is an error). All STEM.<n>.tga (or
// STEM(<n>).tga) in the directory count; they must be exactly 1..N (0..N-1).
// Throws atlas::Error naming the missing slice on a gap, and naming the file
// when none exists.
std::vector<fs::path> find_tga_slices(const fs::path& first_slice);

// Reads the stack as a field with `channels` (1..4) channels (R, G, B, A),
// 8-bit values to 0..1 (v / 255); channels a slice lacks read as 0 (alpha 1;
// a grey slice is R). Every slice must have the first one's size (the error
// names the file).
Field3D read_tga_slices(const fs::path& first_slice, Box3d bounds, int channels = 4, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
