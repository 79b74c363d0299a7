// DDS files and their manifests (see atlas/io/dds_file.h): the file side of the compress
// module, which itself works on memory only.
#include "atlas/io/dds_file.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace atlas::io {

namespace fs = std::filesystem;
using namespace atlas::compress;

namespace {
// Header and data written as they are (no file-sized copy of the texture);
// every write and the close checked.
void write_dds_checked(const fs::path& path, const DdsTexture& tex) {
    const std::vector<uint8_t> header = encode_dds_header(tex);
    write_file_checked(path, {{header.data(), header.size()}, {tex.data.data(), tex.data.size()}});
}
} // namespace

void write_dds_file(const fs::path& path, const DdsTexture& tex) {
    write_file_atomic(path, [&](const fs::path& tmp) { write_dds_checked(tmp, tex); });
}

DdsTexture read_dds_file(const fs::path& path) {
    const std::string s = read_file_bytes(path);
    return decode_dds(std::vector<uint8_t>(s.begin(), s.end()), path.string());
}

std::optional<TextureManifest> read_dds_manifest(const fs::path& dds) {
    fs::path side = dds;
    side += ".json";
    if (!fs::exists(side)) return std::nullopt;
    return TextureManifest::from_json(read_file_bytes(side), side.string());
}

namespace {
// Textures up to this many texels get the bound of every quality level in a bound error
// (encoded again at each; a 128^3 BC4 volume takes about a second per level).
constexpr uint64_t kGuideTexels = uint64_t(1) << 21;

// The guaranteed max error of an encoding over every texel and decoder, the missed blocks included.
double reached_bound(const CompressReport& r) {
    double reach = r.bound_max_error;
    for (const BlockMiss& b : r.blocks_over_bound) reach = std::max(reach, double(b.best_error));
    return reach;
}

// Rounded up to three significant digits, so a bound printed from it passes.
double round_up_3(double v) {
    if (!(v > 0) || !std::isfinite(v)) return v;
    const double unit = std::pow(10.0, std::floor(std::log10(v)) - 2);
    return std::ceil(v / unit) * unit;
}
} // namespace

CompressReport compress_to_dds(const Field3D& field, const fs::path& path, const CompressOptions& o, const ProgressSink* progress) {
    EncodedTexture enc = encode_texture(field, o, progress);
    enc.report.file = path.string();
    if (!enc.report.blocks_over_bound.empty() && !o.allow_over_bound) {
        std::ostringstream msg;
        msg << "compress: " << enc.report.blocks_over_bound.size() << " block(s) cannot meet the bound";
        if (o.max_error) msg << " max_error " << *o.max_error;
        if (o.one_sided_below) msg << (o.max_error ? " with" : "") << " one-sided below";
        msg << " for format '" << format_name(o.format) << "'; first (DDS texel x, row from the top, slice):";
        for (size_t i = 0; i < std::min<size_t>(5, enc.report.blocks_over_bound.size()); ++i) {
            const BlockMiss& b = enc.report.blocks_over_bound[i];
            msg << " [mip " << b.mip << " layer " << b.array_index << " block at (" << b.x << ", " << b.y << ", " << b.z
                << ") best error " << b.best_error << (b.one_sided_failed ? ", one-sided failed" : "") << "]";
        }
        // What the format does reach here: its worst block over every decoder model
        // (the guaranteed figure of the file it would have written).
        const double reach = reached_bound(enc.report);
        if (o.max_error && reach > 0 && std::isfinite(reach)) {
            char buf[160];
            std::snprintf(buf, sizeof buf, "; this encoding reaches max_error %.3g here (its worst block)", round_up_3(reach));
            msg << buf;
            // The other quality levels, when the texture is small enough to encode again (an
            // editor's slider move should learn where the bound is within reach, not only fail).
            const uint64_t texels = uint64_t(field.nx()) * uint64_t(field.ny()) * uint64_t(field.nz());
            if (texels <= kGuideTexels) {
                msg << "; at quality";
                const char* sep = " ";
                for (Quality q : {Quality::Fast, Quality::Normal, Quality::Best}) {
                    double r = reach;
                    if (q != o.quality) {
                        CompressOptions other = o;
                        other.quality = q;
                        r = reached_bound(encode_texture(field, other).report);
                    }
                    std::snprintf(buf, sizeof buf, "%s%s %.3g", sep, quality_name(q), round_up_3(r));
                    msg << buf;
                    sep = ", ";
                }
                msg << " it reaches";
            } else {
                msg << " (atlas compress --sweep gives the bound each quality level reaches)";
            }
            msg << ", so a bound of at least that passes";
        }
        msg << " (allow_over_bound writes the file anyway, with the bound it reached in its manifest)";
        throw BoundError(msg.str(), enc.report);
    }
    if (!enc.report.blocks_over_bound.empty() && enc.manifest.max_error) {
        // Written over the bound on request: the manifest states the bound the file holds, not the
        // one asked for (an importer trusting max_error would be wrong by the miss).
        enc.manifest.requested_max_error = enc.manifest.max_error;
        enc.manifest.max_error = float(round_up_3(reached_bound(enc.report)));
    }
    const std::string manifest = enc.manifest.to_json();
    StagedOutputs staged(path.parent_path().empty() ? fs::path(".") : path.parent_path());
    write_dds_checked(staged.stage(path.filename()), enc.dds);
    fs::path side = path.filename();
    side += ".json";
    write_file_checked(staged.stage(side), manifest.data(), manifest.size());
    staged.commit();
    return enc.report;
}

CompressReport compress_to_dds(const Field2D& field, const fs::path& path, const CompressOptions& o, const ProgressSink* progress) {
    Field3D f3(Vec3i{{field.width(), field.height(), 1}}, field.channels(),
               Box3d{{{field.bounds().min[0], field.bounds().min[1], 0}}, {{field.bounds().max[0], field.bounds().max[1], 1}}},
               field.channel_names());
    for (int c = 0; c < field.channels(); ++c) std::copy(field.channel(c).begin(), field.channel(c).end(), f3.channel(c).begin());
    return io::compress_to_dds(f3, path, o, progress);
}

Field3D read_dds(const fs::path& path, Decoder decoder) {
    const DdsTexture tex = io::read_dds_file(path);
    const auto manifest = io::read_dds_manifest(path);
    return decode_texture(tex, manifest ? &*manifest : nullptr, decoder);
}

CompressReport verify_dds(const fs::path& path, const Field3D& source, DecoderSet decoders, const std::vector<int>& channels) {
    const DdsTexture tex = io::read_dds_file(path);
    const auto manifest = io::read_dds_manifest(path);
    CompressReport r = verify_texture(tex, manifest ? &*manifest : nullptr, source, decoders, channels, path.string());
    r.file = path.string();
    return r;
}

} // namespace atlas::io
