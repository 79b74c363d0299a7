// Field -> DDS texture: mapping, validation, mips, parallel block encoding, bound
// accounting, manifest (in memory; io writes the files).
#include "atlas/compress/bc1.h"
#include "atlas/compress/bc1_scalar.h"
#include "atlas/compress/bc4.h"
#include "atlas/compress/bc6h.h"
#include "atlas/core/error.h"
#include "atlas/core/parallel.h"
#include "half.h"
#include "mips.h"
#include "texture_internal.h"

#include <chrono>
#include <tuple>
#include <cmath>
#include <cstring>
#include <sstream>

namespace atlas::compress {

namespace {

using detail::LevelData;
using detail::MapKind;

struct BlockOutcome {
    float err = 0; // normalized
    bool one_sided_ok = true;
};

// Min and max over the encoded channels ({+inf, -inf} when there are none).
std::pair<float, float> data_range(const Field3D& field, const std::vector<int>& chans) {
    float lo = INFINITY, hi = -INFINITY;
    for (int c : chans)
        for (float v : field.channel(c)) { lo = std::min(lo, v); hi = std::max(hi, v); }
    return {lo, hi};
}

std::string texel_name(const Field3D& f, int c, size_t i) {
    const size_t x = i % size_t(f.nx()), y = (i / size_t(f.nx())) % size_t(f.ny()), z = i / (size_t(f.nx()) * size_t(f.ny()));
    return "texel (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + ") channel '" + f.channel_name(c) + "'";
}

// Quantizes one normalized value for an uncompressed format channel; returns the
// stored code and writes the decoded value. one_sided: the largest code <= n.
uint32_t quantize_unorm(float n, int levels, bool one_sided, float& decoded) {
    const float m = float(levels);
    int q = int(one_sided ? std::floor(n * m) : std::nearbyint(n * m));
    q = std::clamp(q, 0, levels);
    // q / m <= n exactly (the double product of a float and an integer < 2^16 is
    // exact), so a decoder computing q / m in any precision stays <= n.
    if (one_sided)
        while (q > 0 && double(q) > double(n) * double(levels)) --q;
    decoded = float(q) / m;
    return uint32_t(q);
}

uint16_t quantize_half(float n, bool one_sided, float& decoded) {
    const uint16_t h = one_sided ? detail::float_to_half_down(n) : detail::float_to_half(n);
    decoded = detail::half_to_float(h);
    return h;
}

// Encodes one level of an uncompressed format; per-block (4x4 per slice) max errors.
void encode_plain(const LevelData& L, int layer, DxgiFormat f, bool one_sided, uint8_t* out, std::vector<BlockOutcome>& blocks,
                  int bw, int bh) {
    const size_t n = size_t(L.w) * size_t(L.h) * size_t(L.d);
    const int unit = format_unit_bytes(f);
    const auto& P = L.planes[size_t(layer)];
    parallel_blocks(n, 4096, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i != i1; ++i) {
            uint8_t* p = out + i * size_t(unit);
            float dec[4] = {0, 0, 0, 0};
            auto put16 = [&](int k, uint16_t v) { p[2 * k] = uint8_t(v); p[2 * k + 1] = uint8_t(v >> 8); };
            switch (f) {
            case DxgiFormat::R8_UNORM: p[0] = uint8_t(quantize_unorm(P[0][i], 255, one_sided, dec[0])); break;
            case DxgiFormat::R16_UNORM: put16(0, uint16_t(quantize_unorm(P[0][i], 65535, one_sided, dec[0]))); break;
            case DxgiFormat::R16_FLOAT: put16(0, quantize_half(P[0][i], one_sided, dec[0])); break;
            case DxgiFormat::R32_FLOAT: std::memcpy(p, &P[0][i], 4); dec[0] = P[0][i]; break;
            case DxgiFormat::R8G8B8A8_UNORM:
                for (int c = 0; c < 4; ++c) p[c] = uint8_t(quantize_unorm(P[size_t(c)][i], 255, one_sided, dec[c]));
                break;
            case DxgiFormat::R16G16B16A16_FLOAT:
                for (int c = 0; c < 4; ++c) put16(c, quantize_half(P[size_t(c)][i], one_sided, dec[c]));
                break;
            case DxgiFormat::B4G4R4A4_UNORM: {
                uint32_t q[4];
                for (int c = 0; c < 4; ++c) q[c] = quantize_unorm(P[size_t(c)][i], 15, one_sided, dec[c]);
                put16(0, uint16_t(q[2] | (q[1] << 4) | (q[0] << 8) | (q[3] << 12)));
                break;
            }
            default: break;
            }
            (void)dec;
        }
    });
    // Per-block max error, in a fixed order.
    for (size_t i = 0; i < n; ++i) {
        const int x = int(i % size_t(L.w)), y = int((i / size_t(L.w)) % size_t(L.h)), z = int(i / (size_t(L.w) * size_t(L.h)));
        BlockOutcome& b = blocks[(size_t(z) * size_t(bh) + size_t(y / 4)) * size_t(bw) + size_t(x / 4)];
        for (size_t c = 0; c < P.size(); ++c) {
            float d = 0;
            switch (f) {
            case DxgiFormat::R8_UNORM: case DxgiFormat::R8G8B8A8_UNORM: quantize_unorm(P[c][i], 255, one_sided, d); break;
            case DxgiFormat::R16_UNORM: quantize_unorm(P[c][i], 65535, one_sided, d); break;
            case DxgiFormat::B4G4R4A4_UNORM: quantize_unorm(P[c][i], 15, one_sided, d); break;
            case DxgiFormat::R16_FLOAT: case DxgiFormat::R16G16B16A16_FLOAT: quantize_half(P[c][i], one_sided, d); break;
            default: d = P[c][i]; break;
            }
            b.err = std::max(b.err, std::fabs(d - P[c][i]));
            if (d > P[c][i]) b.one_sided_ok = false;
        }
    }
}

// Block b's 16 texels (edge replicated), ch channels interleaved.
template <class Planes>
void gather_block(const LevelData& L, const Planes& P, size_t b, int bw, int bh, int ch, float* src) {
    const int bx = int(b % size_t(bw)), by = int((b / size_t(bw)) % size_t(bh)), z = int(b / (size_t(bw) * size_t(bh)));
    for (int t = 0; t < 16; ++t) {
        const int x = std::min(bx * 4 + t % 4, L.w - 1), y = std::min(by * 4 + t / 4, L.h - 1); // edge replicate
        const size_t at = (size_t(z) * size_t(L.h) + size_t(y)) * size_t(L.w) + size_t(x);
        for (int c = 0; c < ch; ++c) src[ch * t + c] = P[size_t(c)][at];
    }
}

// Encodes one BC level of one layer.
void encode_bc(const LevelData& L, int layer, Format fmt, const BlockOptions& bo, const Bc4Encoder* bc4,
               const ScalarUnpack& unpack, uint8_t* out, std::vector<BlockOutcome>& blocks, int bw, int bh,
               const ProgressSink* progress) {
    const auto& P = L.planes[size_t(layer)];
    const size_t nblocks = size_t(bw) * size_t(bh) * size_t(L.d);
    const bool bc6h = fmt == Format::Bc6hUf16 || fmt == Format::Bc6hSf16;
    const size_t unit = bc6h ? 16 : 8;
    parallel_blocks(nblocks, 64, [&](size_t b0, size_t b1) {
        if (progress) progress->poll();
        if (bc4) { // gathered 64 at a time for encode_blocks (the same results as encode())
            constexpr size_t kRun = 64;
            float src[16 * kRun];
            BlockResult res[kRun];
            for (size_t r0 = b0; r0 < b1; r0 += kRun) {
                const size_t n = std::min(kRun, b1 - r0);
                for (size_t i = 0; i < n; ++i) gather_block(L, P, r0 + i, bw, bh, 1, src + 16 * i);
                bc4->encode_blocks(src, n, out + r0 * unit, res);
                for (size_t i = 0; i < n; ++i) blocks[r0 + i] = {res[i].max_error, res[i].one_sided_ok};
            }
            return;
        }
        for (size_t b = b0; b != b1; ++b) {
            float src[48];
            gather_block(L, P, b, bw, bh, (fmt == Format::Bc1 || bc6h) ? 3 : 1, src);
            BlockResult res;
            uint8_t* dst = out + b * unit;
            if (bc6h) res = encode_bc6h_block(src, fmt == Format::Bc6hSf16, bo, dst);
            else if (fmt == Format::Bc1) res = encode_bc1_block(src, bo, dst);
            else res = encode_bc1_scalar_block(src, unpack, bo, dst); // bc1-scalar (BC4 took the run path above)
            blocks[b] = {res.max_error, res.one_sided_ok};
        }
    });
}

} // namespace

const char* type_encoding_name(TypeEncoding e) { return e == TypeEncoding::GpuPro7 ? "gpu_pro_7" : "atlas"; }

TypeEncoding parse_type_encoding(const std::string& name) {
    if (name == "atlas") return TypeEncoding::Atlas;
    if (name == "gpu_pro_7") return TypeEncoding::GpuPro7;
    throw Error("unknown type_encoding '" + name + "' (expected 'atlas' or 'gpu_pro_7')");
}

namespace {
bool is_type_channel(const std::string& name) { return name == "type" || name == "top_type" || name == "bottom_type"; }
// gpu_pro_7's type re-encoding (docs/compression.md): monotonic, so a range maps through it.
float gpu_pro_7_type(float t) { return std::min(1.0f, 1.5f * t); }

// How many channels the format stores (bc1-scalar: one, spread over RGB).
int stored_channel_count(Format f) { return f == Format::Bc1Scalar ? 1 : format_channels(dxgi_format(f)); }

// The stored channels: those selected, else the first ones the format holds.
std::vector<int> stored_channels(const Field3D& field, const CompressOptions& o, int stored) {
    std::vector<int> chans = o.channels;
    if (chans.empty())
        for (int c = 0; c < std::min(stored, field.channels()); ++c) chans.push_back(c);
    return chans;
}
} // namespace

bool maps_by_own_range(const CompressOptions& o) {
    return !o.value_range && detail::map_kind(dxgi_format(o.format)) != MapKind::Float;
}

std::optional<std::pair<float, float>> own_value_range(const Field3D& field, const CompressOptions& o) {
    if (!maps_by_own_range(o)) return std::nullopt;
    float lo = INFINITY, hi = -INFINITY;
    for (int c : stored_channels(field, o, stored_channel_count(o.format))) {
        if (c < 0 || c >= field.channels()) continue; // encode_texture refuses it
        auto [clo, chi] = data_range(field, {c});
        if (o.type_encoding == TypeEncoding::GpuPro7 && is_type_channel(field.channel_name(c))) clo = gpu_pro_7_type(clo), chi = gpu_pro_7_type(chi);
        lo = std::min(lo, clo);
        hi = std::max(hi, chi);
    }
    return std::make_pair(lo, hi);
}

std::pair<float, float> mapped_value_range(std::pair<float, float> data) {
    if (!(data.second >= data.first)) return {0.0f, 1.0f};
    if (!(data.second > data.first)) return {data.first, data.first + 1.0f};
    return data;
}

EncodedTexture encode_texture(const Field3D& field, const CompressOptions& o, const ProgressSink* progress) {
    if (o.type_encoding == TypeEncoding::GpuPro7) {
        // The type channels re-encoded (t' = min(1, 1.5 t)) in a copy; the bound then holds for
        // the converted values, which are what the texture stores.
        const std::vector<int> chans = stored_channels(field, o, stored_channel_count(o.format));
        Field3D converted = field;
        int found = 0;
        for (int c : chans)
            if (c >= 0 && c < field.channels() && is_type_channel(field.channel_name(c))) {
                for (float& t : converted.channel(c)) t = gpu_pro_7_type(t);
                ++found;
            }
        if (!found) {
            std::string have;
            for (int c : chans) have += (have.empty() ? "" : ", ") + (c >= 0 && c < field.channels() ? field.channel_name(c) : "?");
            throw Error("compress: type_encoding gpu_pro_7 re-encodes channels named type, top_type or bottom_type, and none is stored "
                        "(stored: " + have + "); leave type_encoding at atlas for data without a cloud type");
        }
        CompressOptions inner = o;
        inner.type_encoding = TypeEncoding::Atlas;
        EncodedTexture e = encode_texture(converted, inner, progress);
        e.manifest.type_encoding = type_encoding_name(TypeEncoding::GpuPro7);
        for (std::string& m : e.manifest.channel_meanings)
            if (is_type_channel(m)) m += " (gpu_pro_7: 0 stratus, 0.5 stratocumulus, 1 cumulus and cumulonimbus)";
        return e;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const bool bc6h = o.format == Format::Bc6hUf16 || o.format == Format::Bc6hSf16;
    if (bc6h && o.one_sided_below)
        throw Error(std::string("compress: one-sided below is not supported for format '") + format_name(o.format) +
                    "' (use bc4, bc1-scalar or an uncompressed format for one-sided data)");
    const DxgiFormat dx = dxgi_format(o.format);
    const bool scalar = o.format == Format::Bc1Scalar;
    const int stored = stored_channel_count(o.format);
    std::vector<int> chans = stored_channels(field, o, stored);
    if (int(chans.size()) > stored)
        throw Error(std::string("compress: format '") + format_name(o.format) + "' stores " + std::to_string(stored) +
                    " channel(s), " + std::to_string(chans.size()) + " were selected");
    for (int c : chans)
        if (c < 0 || c >= field.channels())
            throw Error("compress: channel index " + std::to_string(c) + " out of range (the field has " + std::to_string(field.channels()) + ")");
    if (o.mip_levels < 0) throw Error("compress: mip_levels must be >= 0 (0 = full chain), got " + std::to_string(o.mip_levels));
    if (o.max_error && !(*o.max_error >= 0 && std::isfinite(*o.max_error)))
        throw Error("compress: max_error must be a finite value >= 0");
    if ((o.format == Format::Bc1Scalar) && o.decoders == 0) throw Error("compress: the decoder set is empty");

    // NaN / Inf are errors naming the texel.
    for (int c : chans) {
        auto s = field.channel(c);
        for (size_t i = 0; i < s.size(); ++i)
            if (!std::isfinite(s[i]))
                throw Error("compress: source " + texel_name(field, c, i) + " is " + (std::isnan(s[i]) ? "NaN" : "infinite") +
                            " (clean the field before encoding)");
    }

    detail::Mapping map;
    map.kind = detail::map_kind(dx);
    if (map.kind != MapKind::Float) {
        if (o.value_range) {
            map.lo = o.value_range->first;
            map.hi = o.value_range->second;
            if (!(map.hi > map.lo) || !std::isfinite(map.lo) || !std::isfinite(map.hi))
                throw Error("compress: value_range must be finite with lo < hi");
        } else {
            std::tie(map.lo, map.hi) = mapped_value_range(data_range(field, chans));
        }
    } else if (dx == DxgiFormat::R16_FLOAT || dx == DxgiFormat::R16G16B16A16_FLOAT || bc6h) {
        for (int c : chans)
            for (size_t i = 0; i < field.channel(c).size(); ++i) {
                const float v = field.channel(c)[i];
                if (std::fabs(v) > 65504.0f)
                    throw Error("compress: source " + texel_name(field, c, i) + " = " + std::to_string(v) +
                                " exceeds the half-float range (65504)");
                // BC6H UF16 stores no sign: negative values are an error, not a silent clamp.
                if (o.format == Format::Bc6hUf16 && v < 0.0f)
                    throw Error("compress: source " + texel_name(field, c, i) + " = " + std::to_string(v) +
                                " is negative; format 'bc6h' (UF16) stores values >= 0 (use bc6h-sf16)");
            }
    }
    const float nmin = map.kind == MapKind::Snorm ? -1.0f : 0.0f;
    auto src_double = [&](float n) { return map.to_src_exact(n); };
    const double slope = (map.kind == MapKind::Snorm ? 0.5 : 1.0) * (double(map.hi) - double(map.lo)); // d src / d n
    double map_slack = 0; // max |src_double(n) - v| over the stored texels (the mapping's own rounding)

    const bool volume = field.nz() > 1 && !o.as_array;
    const int layers = volume ? 1 : field.nz();
    LevelData L0;
    L0.w = field.nx();
    L0.h = field.ny();
    L0.d = volume ? field.nz() : 1;
    const size_t slice = size_t(L0.w) * size_t(L0.h) * size_t(L0.d);
    // Each plane allocated in place: assign() with a prototype would hold the
    // prototype and its copy at once (twice the planes, 256 MiB more on a
    // 512x512x64 RGBA volume, seen with heaptrack). Not zero-filled: every texel
    // is written below.
    L0.planes.resize(size_t(layers));
    for (auto& layer_planes : L0.planes) {
        layer_planes.resize(size_t(stored));
        for (auto& plane : layer_planes) plane.resize(slice);
    }
    for (int l = 0; l < layers; ++l)
        for (int c = 0; c < stored; ++c) {
            auto& dst = L0.planes[size_t(l)][size_t(c)];
            if (c >= int(chans.size())) { // missing channels: colour 0, alpha 1
                std::fill(dst.begin(), dst.end(), (c == 3) ? 1.0f : 0.0f);
                continue;
            }
            auto s = field.channel(chans[size_t(c)]);
            for (size_t i = 0; i < slice; ++i) {
                // DDS rows run top-down (row 0 is the top of the picture, as every viewer
                // and engine shows it); field rows run y-up. See docs/formats.md.
                const size_t src_i = size_t(l) * slice + detail::dds_row_flip(i, L0.w, L0.h);
                const float v = s[src_i];
                float n = map.to_norm(v);
                if (map.kind != MapKind::Float) {
                    if (n < nmin - 1e-6f || n > 1.0f + 1e-6f)
                        throw Error("compress: source " + texel_name(field, chans[size_t(c)], src_i) + " = " +
                                    std::to_string(v) + " lies outside value_range [" + std::to_string(map.lo) + ", " +
                                    std::to_string(map.hi) + "]");
                    n = std::clamp(n, nmin, 1.0f);
                }
                // One-sided: the normalized source must map back to <= the source, as an
                // engine computes it in double (the float mapping can round an ulp down).
                if (o.one_sided_below && n > nmin && src_double(n) > double(v)) {
                    // Jump to the value that maps to v, then step by ulps (near SNORM's 0
                    // an ulp of n is far below a source ulp: stepping alone takes ~10^5 steps).
                    float m = float(double(n) - (src_double(n) - double(v)) / slope);
                    if (!(m < n)) m = std::nextafter(n, -INFINITY);
                    n = std::max(m, nmin);
                    while (n > nmin && src_double(n) > double(v)) n = std::nextafter(n, -INFINITY);
                }
                if (map.kind != MapKind::Float) map_slack = std::max(map_slack, std::fabs(src_double(n) - double(v)));
                dst[i] = n;
            }
        }

    int full = 1;
    for (int s = std::max({L0.w, L0.h, L0.d}); s > 1; s >>= 1) ++full;
    const int mips = o.mip_levels == 0 ? full : std::min(o.mip_levels, full);
    std::vector<LevelData> levels;
    levels.push_back(std::move(L0));
    for (int m = 1; m < mips; ++m) levels.push_back(detail::reduce_level(levels.back(), volume, o.one_sided_below));

    EncodedTexture out;
    DdsTexture& tex = out.dds;
    tex.format = dx;
    tex.width = field.nx();
    tex.height = field.ny();
    tex.depth = volume ? field.nz() : 1;
    tex.volume = volume;
    tex.array_size = layers;
    tex.mip_levels = mips;
    tex.legacy_header = o.legacy_bc1_header && dx == DxgiFormat::BC1_UNORM;
    tex.data.assign(tex.total_bytes(), 0);

    BlockOptions bo;
    bo.quality = o.quality;
    bo.one_sided_below = o.one_sided_below;
    bo.decoders = o.decoders == 0 ? kReferenceOnly : o.decoders;
    // BC6H decoding is integer-exact in the specification: every decoder model gives the
    // same values, so one decode measures the guarantee for all of them.
    if (bc6h) bo.decoders = kReferenceOnly;
    // Uncompressed formats have one decoding too (every model reads the stored
    // value), so the guarantee for all of `decoders` is verified with one decode.
    const DecoderSet verify_decoders = is_block_compressed(dx) ? bo.decoders : kReferenceOnly;
    const double scale = map.scale();
    // Block errors are float bounds in normalized units: the exact error of a block is at
    // most (err (1 + 2^-22) + kNormSlack) * scale (1 + 1e-12) + map_slack (float rounding
    // of the error itself and of uncompressed decodes, the double scaling, the mapping's
    // rounding), so the encoders aim below E by that much and a block counts as missing
    // E on that bound: max_error then holds for a decoder computing in double.
    constexpr double kNormSlack = 1.0 / 8388608.0; // 2^-23, an ulp at 1
    // Float formats store values as is: their errors are float differences (exact or
    // within 2^-24 relative), with no mapping and no absolute slack.
    const double norm_slack = map.kind == MapKind::Float ? 0.0 : kNormSlack;
    auto exact_bound = [&](float err) { return (double(err) * (1.0 + 1.0 / 4194304.0) + norm_slack) * scale * (1.0 + 1e-12) + map_slack; };
    bo.max_error = o.max_error ? float(std::max(0.0, ((*o.max_error - map_slack) / (scale * (1.0 + 1e-12)) - norm_slack) / (1.0 + 1.0 / 4194304.0)))
                               : -1.0f;
    std::unique_ptr<Bc4Encoder> bc4;
    if (o.format == Format::Bc4 || o.format == Format::Bc4Snorm) bc4 = std::make_unique<Bc4Encoder>(o.format == Format::Bc4Snorm, bo);
    const ScalarUnpack unpack = bc1_scalar_unpack(bo.decoders);

    CompressReport& rep = out.report;
    for (int l = 0; l < layers; ++l)
        for (int m = 0; m < mips; ++m) {
            const LevelData& L = levels[size_t(m)];
            const int bw = std::max(1, (L.w + 3) / 4), bh = std::max(1, (L.h + 3) / 4);
            std::vector<BlockOutcome> blocks(size_t(bw) * size_t(bh) * size_t(L.d));
            uint8_t* dst = tex.data.data() + tex.offset(l, m);
            if (is_block_compressed(dx)) encode_bc(L, l, o.format, bo, bc4.get(), unpack, dst, blocks, bw, bh, progress);
            else encode_plain(L, l, dx, o.one_sided_below, dst, blocks, bw, bh);
            for (size_t b = 0; b < blocks.size(); ++b) {
                const bool over = (o.max_error && exact_bound(blocks[b].err) > double(*o.max_error)) ||
                                  (o.one_sided_below && !blocks[b].one_sided_ok);
                if (!over) continue;
                BlockMiss miss;
                miss.x = int(b % size_t(bw)) * 4;
                miss.y = int((b / size_t(bw)) % size_t(bh)) * 4;
                miss.z = int(b / (size_t(bw) * size_t(bh)));
                miss.array_index = l;
                miss.mip = m;
                miss.best_error = float(exact_bound(blocks[b].err));
                miss.one_sided_failed = o.one_sided_below && !blocks[b].one_sided_ok;
                rep.blocks_over_bound.push_back(miss);
            }
            if (progress && progress->on_progress) {
                ProgressEvent ev;
                ev.task = "compress";
                ev.done = l * mips + m + 1;
                ev.total = layers * mips;
                ev.fraction = double(ev.done) / ev.total;
                progress->on_progress(ev);
            }
        }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    TextureManifest& man = out.manifest;
    man.encoding = format_name(o.format);
    man.dxgi_format = dxgi_format_name(dx);
    man.width = tex.width;
    man.height = tex.height;
    man.depth = tex.depth;
    man.array_size = tex.array_size;
    man.mip_levels = mips;
    man.volume = volume;
    for (int c = 0; c < stored; ++c) {
        if (c < int(o.channel_meanings.size())) man.channel_meanings.push_back(o.channel_meanings[size_t(c)]);
        else if (c < int(chans.size())) man.channel_meanings.push_back(field.channel_name(chans[size_t(c)]));
        else man.channel_meanings.push_back(c == 3 ? "alpha (constant 1)" : "unused (constant 0)");
    }
    man.mapping = map.kind == MapKind::Float ? "identity" : map.kind == MapKind::Snorm ? "snorm: value = lo + (n + 1) / 2 * (hi - lo)"
                                                                                        : "unorm: value = lo + n * (hi - lo)";
    if (scalar) man.mapping = "bc1-scalar: n = dot(rgb, unpack_weights); value = lo + n * (hi - lo)";
    if (map.kind == MapKind::Float) {
        // Identity mapping: the range is the data's own min and max, for the
        // importer's information (and the PSNR's peak); nothing is rescaled.
        auto [lo, hi] = data_range(field, chans);
        if (chans.empty() || !(hi >= lo)) { lo = 0; hi = 1; }
        man.range_lo = lo;
        man.range_hi = hi;
    } else {
        man.range_lo = map.lo;
        man.range_hi = map.hi;
    }
    man.max_error = o.max_error;
    man.one_sided_below = o.one_sided_below;
    for (Decoder d : decoders_in(bo.decoders)) man.decoders.push_back(decoder_name(d));
    man.mip_filter = o.one_sided_below ? "min" : "box";
    man.unpack_weights = unpack.weights;
    man.world_bounds = field.bounds();
    for (int c : chans)
        if (is_type_channel(field.channel_name(c))) man.type_encoding = type_encoding_name(TypeEncoding::Atlas);

    // The float levels are encoded: free them before the verify decodes (a
    // 512x512x64 RGBA volume's levels are ~290 MiB besides the texture).
    std::vector<LevelData>().swap(levels);
    // Level-0 errors under every decoder, from the encoded bytes.
    const auto t_verify = std::chrono::steady_clock::now();
    CompressReport v = verify_texture(tex, &man, field, verify_decoders, chans, "encoded texture");
    v.verify_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_verify).count();
    v.blocks_over_bound = std::move(rep.blocks_over_bound);
    rep = std::move(v);
    rep.format = man.encoding;
    rep.requested_max_error = o.max_error;
    rep.one_sided_below = o.one_sided_below;
    rep.value_range = {man.range_lo, man.range_hi};
    rep.encode_seconds = seconds;
    rep.texels = uint64_t(field.nx()) * uint64_t(field.ny()) * uint64_t(field.nz());
    rep.texels_per_second = seconds > 0 ? double(rep.texels) / seconds : 0;
    rep.bytes = tex.data.size();
    return out;
}

std::vector<SweepRow> sweep(const Field3D& field, const CompressOptions& options) {
    std::vector<SweepRow> rows;
    for (Quality q : {Quality::Fast, Quality::Normal, Quality::Best}) {
        CompressOptions o = options;
        o.quality = q;
        EncodedTexture e = encode_texture(field, o);
        SweepRow r;
        r.quality = q;
        r.max_error = e.report.bound_max_error;
        for (double x : e.report.rmse) r.rmse = std::max(r.rmse, x);
        r.seconds = e.report.encode_seconds;
        rows.push_back(r);
    }
    return rows;
}

std::string sweep_csv(const std::vector<SweepRow>& rows) {
    std::ostringstream s;
    s.precision(9);
    s << "quality,max_error,rmse,seconds\n";
    for (const SweepRow& r : rows) s << quality_name(r.quality) << ',' << r.max_error << ',' << r.rmse << ',' << r.seconds << '\n';
    return s.str();
}

std::string CompressReport::to_json() const {
    std::ostringstream s;
    s.precision(9);
    auto arr = [&](const std::vector<double>& v) {
        s << "[";
        for (size_t i = 0; i < v.size(); ++i) {
            if (i) s << ", ";
            if (std::isfinite(v[i])) s << v[i]; else s << "null";
        }
        s << "]";
    };
    s << "{\n  \"format\": \"" << format << "\",\n  \"file\": \"";
    for (char c : file) { if (c == '"' || c == '\\') s << '\\'; s << c; }
    s << "\",\n  \"width\": " << width << ", \"height\": " << height << ", \"depth\": " << depth << ", \"array_size\": " << array_size
      << ", \"mip_levels\": " << mip_levels << ", \"channels\": " << channels << ",\n";
    s << "  \"value_range\": [" << value_range.first << ", " << value_range.second << "],\n";
    s << "  \"max_error\": "; arr(max_error); s << ",\n  \"rmse\": "; arr(rmse); s << ",\n  \"psnr\": "; arr(psnr);
    s << ",\n  \"bound_max_error\": " << bound_max_error << ",\n  \"requested_max_error\": ";
    if (requested_max_error) s << *requested_max_error; else s << "null";
    s << ",\n  \"one_sided\": \"" << (one_sided_below ? "below" : "none") << "\",\n  \"blocks_over_bound\": [";
    for (size_t i = 0; i < blocks_over_bound.size(); ++i) {
        const BlockMiss& b = blocks_over_bound[i];
        s << (i ? ", " : "") << "{\"x\": " << b.x << ", \"y\": " << b.y << ", \"z\": " << b.z << ", \"array_index\": " << b.array_index
          << ", \"mip\": " << b.mip << ", \"best_error\": " << b.best_error << ", \"one_sided_failed\": " << (b.one_sided_failed ? "true" : "false") << "}";
    }
    s << "],\n  \"decoders\": [";
    for (size_t i = 0; i < per_decoder.size(); ++i) {
        const DecoderStats& d = per_decoder[i];
        s << (i ? ", " : "") << "\n    {\"decoder\": \"" << decoder_name(d.decoder) << "\", \"max_error\": ";
        arr(d.max_error);
        s << ", \"max_over\": " << d.max_over << ", \"one_sided_violations\": " << d.one_sided_violations << ", \"mean_under\": " << d.mean_under << "}";
    }
    s << "],\n  \"encode_seconds\": " << encode_seconds << ",\n  \"verify_seconds\": " << verify_seconds << ",\n  \"texels\": " << texels << ",\n  \"texels_per_second\": " << texels_per_second
      << ",\n  \"bytes\": " << bytes << "\n}\n";
    return s.str();
}

} // namespace atlas::compress
