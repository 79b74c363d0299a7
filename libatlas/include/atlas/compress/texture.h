// atlas/compress/texture.h - fields to DDS textures with error bounds, and back.
//
// This is the API the CLI (`atlas compress / decompress / info`) and the graph
// writer nodes call. Values are mapped from the source range [lo, hi] to the
// format's normalized range (UNORM [0,1], SNORM [-1,1]; float formats are stored
// as is); every error below is in SOURCE units unless it says otherwise.
// Determinism: the written bytes depend only on the field and the options, never
// on the thread count (blocks are encoded independently, reductions are ordered).
// Thread-safety: the functions are reentrant; they use TBB internally.
//
// Implemented in texture_encode.cpp, texture_decode.cpp, texture_format.cpp, manifest.cpp (src/compress/).
#pragma once

#include "atlas/compress/block.h"
#include "atlas/compress/dds.h"
#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/core/progress.h"

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace atlas::compress {

// Bump whenever the encoder writes other bytes for the same field and options, so
// cooked outputs and cached textures from an older encoder are not reused.
// 2: DDS rows top-down; exact (double) one-sided and max-error bounds; bc1-scalar
// one-sided search that never falls back to black.
// 3: bc1-scalar single-entry search for near-constant blocks and normal's nudges.
// 4: BC4 fast / normal one-pass key evaluation (ties within 8 ulps may pick differently).
// 5: bc1-scalar one-sided fit with an endpoint or both unused, shared-R bottom after the
// first pass, single-entry search for blocks whose spread is under their error.
// 6: BC1 RGB normal also starts from the other three box diagonals, 4 power iterations.
// 7: BC1 RGB given max_error minimises the squared error within it (not the max error first).
// 8: BC1 RGB ranks entries by their squared error in float; given max_error, a start within
// it skips the box diagonals for an inset one, the +-1 moves after the first round stay in
// the incumbent's colour mode, and a block still far off searches again from two clusters.
constexpr int kEncoderVersion = 8;

// The most mip levels a front end asks for by number (a 65536 texture has 17
// levels; "full" asks for all of them).
constexpr int kMaxMipLevels = 16;

enum class Format {
    Bc1,       // RGB, 4 bpp
    Bc1Scalar, // one channel across RGB565 (Nubis field data), 4 bpp
    Bc4,       // one channel UNORM, 4 bpp
    Bc4Snorm,  // one channel SNORM, 4 bpp
    Bc6hUf16,  // RGB half float, unsigned, 8 bpp (values stored as is; negative input is an error)
    Bc6hSf16,  // RGB half float, signed, 8 bpp (one-sided bounds are refused for BC6H)
    R8, R16, R16F, R32F, Rgba8, Rgba16F, Rgba4,
};
// "bc1", "bc1-scalar", "bc4", "bc4-snorm", "bc6h", "bc6h-sf16", "r8", "r16", "r16f",
// "r32f", "rgba8", "rgba16f", "rgba4".
const char* format_name(Format f);
Format parse_format(const std::string& name); // throws atlas::Error listing the names
std::string format_names();                   // "bc1, bc1-scalar, ...": every name parse_format takes
DxgiFormat dxgi_format(Format f);

// How channels named type, top_type and bottom_type encode the cloud type (docs/ndf.md): the
// sources differ, so an engine texture names its convention in the manifest.
//   Atlas    0 stratus, 1/3 stratocumulus, 2/3 cumulus, 1 cumulonimbus (Atlas's NDF set)
//   GpuPro7  0 stratus, 0.5 stratocumulus, 1 cumulus (HZD, GPU Pro 7 ch. 4): t' = min(1, 1.5 t),
//            so cumulonimbus is stored as cumulus
enum class TypeEncoding { Atlas, GpuPro7 };
const char* type_encoding_name(TypeEncoding e);
TypeEncoding parse_type_encoding(const std::string& name); // throws atlas::Error listing the names

struct CompressOptions {
    Format format = Format::Bc4;
    TypeEncoding type_encoding = TypeEncoding::Atlas;
    Quality quality = Quality::Normal;
    // Guarantee |decoded - source| <= max_error (source units) for every texel of
    // every mip level under every decoder in `decoders`; blocks that cannot meet it
    // are listed in the report and make compress_to_dds throw BoundError unless
    // allow_over_bound.
    std::optional<float> max_error;
    // Guarantee decoded <= source for every texel under every decoder in `decoders`
    // (bc4, bc1-scalar, uncompressed formats; BC1 RGB per channel when reachable).
    // Mips are then min-reduced so every mip texel is <= the level-0 texels it covers.
    bool one_sided_below = false;
    bool allow_over_bound = false;
    // 1 = no mips, 0 = full chain, n = n levels (front ends accept 1..kMaxMipLevels or
    // "full"). Volumes get 3D mips (2x2x2).
    int mip_levels = 1;
    DecoderSet decoders = kAllDecoders;
    // Source range mapped to the normalized range; empty = the data's min and max.
    std::optional<std::pair<float, float>> value_range;
    // Field channels to store (empty = the first ones the format needs; missing
    // colour channels are 0, missing alpha is 1).
    std::vector<int> channels;
    // The same by name, as the front ends' 'channels' option gives them;
    // resolve_channel_names (compress_options.h) turns them into `channels`.
    std::vector<std::string> channel_names;
    // A Field3D with nz > 1 becomes a 2D array instead of a volume texture.
    bool as_array = false;
    // BC1 textures that are not arrays get the legacy "DXT1" FourCC header instead
    // of DX10 (same data; OpenImageIO 2.4 reads only that for BC1).
    bool legacy_bc1_header = true;
    // Free text for the manifest's channel meanings (default: the field's names).
    std::vector<std::string> channel_meanings;
};

// One 4x4 block (per slice) that misses the bound: its texel origin in DDS
// coordinates (x = column, y = row counted from the TOP of the image as the DDS
// stores it, z = slice) and the best error the encoder reached (source units).
// Field texel (x, y_field) lies in DDS row height - 1 - y_field.
struct BlockMiss {
    int x = 0, y = 0, z = 0, array_index = 0, mip = 0;
    float best_error = 0;
    bool one_sided_failed = false;
};

// Errors of the level-0 data under one decoder model.
struct DecoderStats {
    Decoder decoder = Decoder::Reference;
    std::vector<double> max_error;     // per stored channel (worst case inside Conformant's interval)
    double max_over = 0;               // max(decoded - source) over texels and channels (<= 0: one-sided holds)
    uint64_t one_sided_violations = 0; // texel-channels with decoded > source
    double mean_under = 0;             // mean(source - decoded)
};

struct CompressReport {
    std::string format;
    std::string file;
    int width = 0, height = 0, depth = 1, array_size = 1, mip_levels = 1, channels = 1;
    std::pair<float, float> value_range{0.0f, 1.0f};
    // Level 0, Reference decoder, per stored channel, source units.
    std::vector<double> max_error, rmse, psnr;
    double bound_max_error = 0; // max over decoders and channels (the guaranteed figure)
    std::optional<float> requested_max_error;
    bool one_sided_below = false;
    std::vector<BlockMiss> blocks_over_bound;
    std::vector<DecoderStats> per_decoder;
    double encode_seconds = 0;
    double verify_seconds = 0; // decoding the written blocks and measuring the errors above
    double texels_per_second = 0;
    uint64_t texels = 0;
    uint64_t bytes = 0;
    // Keys as named above; stable for --report.
    std::string to_json() const;
};

// Thrown when blocks miss the bound and allow_over_bound is false; carries the report.
class BoundError : public Error {
public:
    BoundError(const std::string& message, CompressReport report) : Error(message), report_(std::move(report)) {}
    const CompressReport& report() const { return report_; }

private:
    CompressReport report_;
};

// The sidecar manifest OUT.dds.json an engine importer reads.
struct TextureManifest {
    std::string encoding;  // format_name()
    std::string dxgi_format;
    int width = 0, height = 0, depth = 1, array_size = 1, mip_levels = 1;
    bool volume = false;
    std::vector<std::string> channel_meanings;
    // value = lo + n * (hi - lo) for UNORM n, lo + (n + 1) / 2 * (hi - lo) for SNORM n,
    // value = n for float formats ("identity").
    std::string mapping;
    float range_lo = 0, range_hi = 1;
    std::optional<float> max_error; // source units, as guaranteed
    // Present when the texture was written over the bound on request (allow_over_bound):
    // the bound asked for; max_error is then the one the file holds.
    std::optional<float> requested_max_error;
    bool one_sided_below = false;
    std::vector<std::string> decoders;
    std::string mip_filter; // "box" or "min"
    std::array<float, 3> unpack_weights{1, 0, 0}; // bc1-scalar: n = dot(rgb, weights)
    // The field's world box (metres), so a decoded texture comes back where it was;
    // absent in manifests written before it existed (decoding then uses 1 m texels at 0).
    std::optional<Box3d> world_bounds;
    // The cloud type convention of the stored type channels (type_encoding_name); empty when
    // no stored channel is a type channel.
    std::string type_encoding;
    std::string to_json() const;
    static TextureManifest from_json(const std::string& text, const std::string& what);
};

// Encodes a field (2D as 1 slice, or 3D as a volume or an array): the DDS texture, its
// manifest and the report; blocks that miss the bound are listed in the report.
// Throws atlas::Error on NaN / Inf input (naming the texel and channel), bad options
// and an unimplemented format. Writing OUT.dds and OUT.dds.json (and BoundError when
// blocks miss the bound): io::compress_to_dds (atlas/io/dds_file.h).
struct EncodedTexture {
    DdsTexture dds;
    TextureManifest manifest;
    CompressReport report;
};
EncodedTexture encode_texture(const Field3D& field, const CompressOptions& options, const ProgressSink* progress = nullptr);

// Whether `options` map values into the format's 0..1 by the data's own min and max: a
// normalised format (unorm or snorm; not the float formats) without value_range.
bool maps_by_own_range(const CompressOptions& options);
// The data's min and max over the stored channels (after a gpu_pro_7 type re-encoding) when
// maps_by_own_range(options); {+inf, -inf} when none is stored; nullopt otherwise. A tiled
// cook gives its tiles the union of theirs as value_range, so every tile quantises as the
// whole world does (docs/scale.md).
std::optional<std::pair<float, float>> own_value_range(const Field3D& field, const CompressOptions& options);
// The range encode_texture maps such data from: the data's min and max; 0..1 without data
// ({+inf, -inf}); lo..lo + 1 for constant data.
std::pair<float, float> mapped_value_range(std::pair<float, float> data);

// Decodes level 0 of every slice / array element to float in source units (the
// manifest's mapping when there is one, else the normalized values; a bc1-scalar
// texture without manifest decodes as RGB). Arrays stack along z. From a file:
// io::read_dds (atlas/io/dds_file.h).
Field3D decode_texture(const DdsTexture& dds, const TextureManifest* manifest, Decoder decoder = Decoder::Reference);

// Decodes level 0 with every decoder in `decoders` and compares to `source`
// (whose stored channels are taken as in `channels`): max error and one-sided error
// per model; `manifest` may be null (values compared as stored). On a file with its
// manifest: io::verify_dds (atlas/io/dds_file.h).
CompressReport verify_texture(const DdsTexture& tex, const TextureManifest* manifest, const Field3D& source,
                              DecoderSet decoders = kAllDecoders, const std::vector<int>& channels = {},
                              const std::string& what = "texture");

// Encodes at each quality level (no file written): error versus time.
struct SweepRow {
    Quality quality;
    double max_error = 0, rmse = 0, seconds = 0;
};
std::vector<SweepRow> sweep(const Field3D& field, const CompressOptions& options);
// "quality,max_error,rmse,seconds" header and one line per row (errors in source units).
std::string sweep_csv(const std::vector<SweepRow>& rows);

} // namespace atlas::compress
