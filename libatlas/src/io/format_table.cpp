// The output formats, their options and their writers. Append new formats at
// the end (the order is what `atlas` and docs list).
#include "format_table.h"

namespace atlas::io::detail {

namespace {
const std::pair<std::string, std::string> kChannels{"channels", "comma-separated channel names to write, in this order (default: all)"};
} // namespace

const std::vector<FormatEntry>& format_table() {
    static const std::vector<FormatEntry> table = {
        {{"exr",
          {".exr"},
          {PortType::Field2D, PortType::Field3D},
          "OpenEXR, 32-bit float (bit-exact) or half; a 3D field is nx x (ny*nz) stacked slices with atlas:* header attributes",
          {{"half", "true: store 16-bit half floats (values beyond +-65504 are an error)"},
           {"meaning", "free text stored in the atlas:channel_meaning attribute"},
           kChannels}},
         write_exr_output},
        {{"png",
          {".png"},
          {PortType::Field2D, PortType::Field3D},
          "PNG, 8 or 16 bits, 1-4 channels, values mapped from 'range'; a 3D field writes one z slice or a montage",
          {{"bits", "8 or 16 (default 8)"},
           {"range", "'lo,hi': the values mapped to 0 and to full scale (default 0,1); outside values clamp"},
           {"slice", "3D fields: the z index to write (default nz/2)"},
           {"montage", "3D fields: true writes every slice tiled in a grid (slice 0 top left)"},
           kChannels}},
         write_image_output},
        {{"tga",
          {".tga"},
          {PortType::Field2D, PortType::Field3D},
          "TGA, 8 bits, 1, 3 or 4 channels, uncompressed, values mapped from 'range'; a 3D field writes one z slice or a montage",
          {{"bits", "8 (TGA holds 8 bits per channel)"},
           {"range", "'lo,hi': the values mapped to 0 and 255 (default 0,1); outside values clamp"},
           {"slice", "3D fields: the z index to write (default nz/2)"},
           {"montage", "3D fields: true writes every slice tiled in a grid (slice 0 top left)"},
           kChannels}},
         write_image_output},
        {{"vdb",
          {".vdb"},
          {PortType::Field3D},
          "OpenVDB, one sparse float fog-volume grid per channel (named after it), voxel centres as in the field",
          {{"tolerance", "values with |v| <= tolerance stay inactive (background 0; default 0)"},
           {"vector3", "true: a 3-channel field becomes one vec3s grid"},
           {"grids", "comma-separated grid names (default: the channel names)"},
           kChannels}},
         write_vdb_output},
        {{"tga-slices",
          {},
          {PortType::Field3D},
          "a stack of 32-bit RGBA TGA files DIR/STEM.001.tga ... one per z (the Nubis voxel cloud pack layout); the path is DIR/STEM",
          {{"range", "'lo,hi': the values mapped to 0 and 255 (default 0,1); outside values clamp"},
           {"alpha", "0..255: alpha where the field has no 4th channel (default 255)"},
           {"channels", "comma-separated channel names for R, G, B, A (up to 4; missing ones fill with 0, alpha with 'alpha')"}}},
         write_tga_slices_output},
        {{"dds",
          {".dds"},
          {PortType::Field2D, PortType::Field3D},
          "DDS texture (2D, array or volume) through the error-bounded compressor, with its manifest FILE.dds.json",
          {{"encoding", "bc1, bc1-scalar, bc4, bc4-snorm, r8, r16, r16f, r32f, rgba8, rgba16f, rgba4 (default rgba16f)"},
           {"quality", "fast, normal (default) or best"},
           {"max_error", "guarantee |decoded - source| <= E for every texel, in source units (else the cook fails)"},
           {"one_sided", "'below': guarantee decoded <= source (SDF field data)"},
           {"allow_over_bound", "true: write even when blocks miss max_error"},
           {"decoders", "decoder models the bounds hold for (default all: reference,nvidia,amd,tool8,conformant)"},
           {"mips", "mip levels, or 'full' (default 1)"},
           {"range", "'lo,hi': source values mapped to 0..1 (default: the data's min and max)"},
           {"array", "true: a 3D field becomes a 2D texture array instead of a volume"},
           kChannels}},
         write_dds_output},
    };
    return table;
}

} // namespace atlas::io::detail
