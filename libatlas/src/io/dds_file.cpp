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
        double reach = enc.report.bound_max_error;
        for (const BlockMiss& b : enc.report.blocks_over_bound) reach = std::max(reach, double(b.best_error));
        if (o.max_error && reach > 0 && std::isfinite(reach)) {
            // Rounded up to three significant digits, so the number printed passes.
            const double unit = std::pow(10.0, std::floor(std::log10(reach)) - 2);
            char buf[160];
            std::snprintf(buf, sizeof buf, "; this encoding reaches max_error %.3g here (its worst block), so a bound of at least that passes",
                          std::ceil(reach / unit) * unit);
            msg << buf;
        }
        msg << " (allow_over_bound writes the file anyway)";
        throw BoundError(msg.str(), enc.report);
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
