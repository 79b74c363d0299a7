// Decoding DDS levels (every format, every decoder model), read_dds and verify_dds.
#include "atlas/compress/bc1.h"
#include "atlas/compress/bc4.h"
#include "atlas/compress/bc6h.h"
#include "atlas/core/error.h"
#include "atlas/core/parallel.h"
#include "half.h"
#include "texture_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace atlas::compress {

namespace detail {

MapKind map_kind(DxgiFormat f) {
    switch (f) {
    case DxgiFormat::R16_FLOAT:
    case DxgiFormat::R32_FLOAT:
    case DxgiFormat::R16G16B16A16_FLOAT:
    case DxgiFormat::BC6H_UF16:
    case DxgiFormat::BC6H_SF16:
        return MapKind::Float;
    case DxgiFormat::BC4_SNORM:
        return MapKind::Snorm;
    default:
        return MapKind::Unorm;
    }
}

DecodedLevel decode_level(const DdsTexture& tex, int layer, int mip, Decoder decoder, bool bc1_scalar, const ScalarUnpack& unpack, int z0,
                          int z1) {
    DecodedLevel L;
    L.w = tex.level_width(mip);
    L.h = tex.level_height(mip);
    const int depth = tex.level_depth(mip);
    if (z1 < 0) z1 = depth;
    if (z0 < 0 || z0 > z1 || z1 > depth)
        throw Error("decode_level: slices [" + std::to_string(z0) + ", " + std::to_string(z1) + ") outside the level's depth " +
                    std::to_string(depth));
    L.d = z1 - z0;
    L.channels = bc1_scalar ? 1 : format_channels(tex.format);
    const size_t n = size_t(L.w) * size_t(L.h) * size_t(L.d);
    L.lo.assign(size_t(L.channels), std::vector<float>(n));
    L.hi.assign(size_t(L.channels), std::vector<float>(n));
    const size_t slice_texels = size_t(L.w) * size_t(L.h);
    const DxgiFormat f = tex.format;
    const uint8_t* const level = tex.data.data() + tex.offset(layer, mip);
    if (is_block_compressed(f)) {
        const int bw = std::max(1, (L.w + 3) / 4), bh = std::max(1, (L.h + 3) / 4);
        const int unit = format_unit_bytes(f);
        const uint8_t* base = level + size_t(z0) * size_t(bh) * size_t(bw) * size_t(unit);
        float lo[48], hi[48];
        const int ch = L.channels;
        // One block's texels into lo and hi (equal where the decode is exact).
        auto decode_block = [&](const uint8_t* blk) {
            if (f == DxgiFormat::BC6H_UF16 || f == DxgiFormat::BC6H_SF16) {
                decode_bc6h_block(blk, f == DxgiFormat::BC6H_SF16, lo); // exact: no decoder tolerance
                std::copy(lo, lo + 48, hi);
            } else if (f == DxgiFormat::BC4_UNORM || f == DxgiFormat::BC4_SNORM) {
                const bool sn = f == DxgiFormat::BC4_SNORM;
                if (decoder == Decoder::Conformant)
                    decode_bc4_interval(blk, sn, decoder_bit(decoder), lo, hi);
                else {
                    decode_bc4_block(blk, sn, decoder, lo);
                    std::copy(lo, lo + 16, hi);
                }
            } else { // BC1
                float rgb[48];
                decode_bc1_block(blk, decoder, rgb);
                float tol[4][3] = {};
                if (decoder == Decoder::Conformant) {
                    const uint16_t c0 = uint16_t(blk[0] | (blk[1] << 8)), c1 = uint16_t(blk[2] | (blk[3] << 8));
                    float ref[4][3];
                    bc1_palette(c0, c1, Decoder::Reference, ref);
                    for (int i = 0; i < 4; ++i)
                        for (int c = 0; c < 3; ++c) tol[i][c] = (c0 <= c1 && i == 3) ? 0.0f : bc1_conformant_tolerance(ref[0][c], ref[1][c]);
                }
                const uint32_t bits = uint32_t(blk[4]) | (uint32_t(blk[5]) << 8) | (uint32_t(blk[6]) << 16) | (uint32_t(blk[7]) << 24);
                for (int t = 0; t < 16; ++t) {
                    const int i = int((bits >> (2 * t)) & 3);
                    if (bc1_scalar) {
                        float tv = 0;
                        for (int c = 0; c < 3; ++c) tv += tol[i][c] * unpack.weights[size_t(c)];
                        // same summation order as decode_bc1_scalar_block
                        const float v = rgb[3 * t] * unpack.weights[0] + rgb[3 * t + 1] * unpack.weights[1] + rgb[3 * t + 2] * unpack.weights[2];
                        lo[t] = v - tv;
                        hi[t] = v + tv;
                    } else
                        for (int c = 0; c < 3; ++c) {
                            lo[3 * t + c] = rgb[3 * t + c] - tol[i][c];
                            hi[3 * t + c] = rgb[3 * t + c] + tol[i][c];
                        }
                }
            }
        };
        // A block with the bytes of the one before decodes the same (empty space is
        // runs of one block): its texels are reused (lo and hi outlive the iteration).
        const uint8_t* prev = nullptr;
        for (int z = 0; z < L.d; ++z)
            for (int by = 0; by < bh; ++by)
                for (int bx = 0; bx < bw; ++bx) {
                    const uint8_t* blk = base + ((size_t(z) * size_t(bh) + size_t(by)) * size_t(bw) + size_t(bx)) * size_t(unit);
                    const bool repeat = prev && std::memcmp(prev, blk, size_t(unit)) == 0;
                    if (!repeat) decode_block(blk);
                    prev = blk;
                    for (int t = 0; t < 16; ++t) {
                        const int x = bx * 4 + t % 4, y = by * 4 + t / 4;
                        if (x >= L.w || y >= L.h) continue;
                        const size_t at = (size_t(z) * size_t(L.h) + size_t(y)) * size_t(L.w) + size_t(x);
                        for (int c = 0; c < ch; ++c) {
                            L.lo[size_t(c)][at] = lo[ch * t + c];
                            L.hi[size_t(c)][at] = hi[ch * t + c];
                        }
                    }
                }
        return L;
    }
    const int unit = format_unit_bytes(f);
    const uint8_t* base = level + size_t(z0) * slice_texels * size_t(unit);
    for (size_t i = 0; i < n; ++i) {
        const uint8_t* p = base + i * size_t(unit);
        float v[4] = {0, 0, 0, 0};
        auto u16 = [&](int k) { return uint16_t(p[2 * k] | (p[2 * k + 1] << 8)); };
        switch (f) {
        case DxgiFormat::R8_UNORM:
            v[0] = float(p[0]) / 255.0f;
            break;
        case DxgiFormat::R16_UNORM:
            v[0] = float(u16(0)) / 65535.0f;
            break;
        case DxgiFormat::R16_FLOAT:
            v[0] = half_to_float(u16(0));
            break;
        case DxgiFormat::R32_FLOAT:
            std::memcpy(&v[0], p, 4);
            break;
        case DxgiFormat::R8G8B8A8_UNORM:
            for (int c = 0; c < 4; ++c) v[c] = float(p[c]) / 255.0f;
            break;
        case DxgiFormat::R16G16B16A16_FLOAT:
            for (int c = 0; c < 4; ++c) v[c] = half_to_float(u16(c));
            break;
        case DxgiFormat::B4G4R4A4_UNORM: {
            const uint16_t w = u16(0);
            v[2] = float(w & 15) / 15.0f;
            v[1] = float((w >> 4) & 15) / 15.0f;
            v[0] = float((w >> 8) & 15) / 15.0f;
            v[3] = float((w >> 12) & 15) / 15.0f;
            break;
        }
        default:
            break;
        }
        for (int c = 0; c < L.channels; ++c) L.lo[size_t(c)][i] = L.hi[size_t(c)][i] = v[c];
    }
    return L;
}

} // namespace detail

Field3D decode_texture(const DdsTexture& tex, const TextureManifest* manifest, Decoder decoder) {
    const bool scalar = manifest && manifest->encoding == "bc1-scalar";
    ScalarUnpack unpack;
    if (scalar) {
        unpack.weights = manifest->unpack_weights;
        unpack.max_value = unpack.weights[0] + unpack.weights[1] + unpack.weights[2];
    }
    detail::Mapping map;
    map.kind = detail::map_kind(tex.format);
    if (manifest) {
        map.lo = manifest->range_lo;
        map.hi = manifest->range_hi;
    } else if (map.kind != detail::MapKind::Float)
        map.kind = detail::MapKind::Float; // normalized values as stored
    const int layers = tex.array_size, depth = tex.depth;
    const int nz = tex.volume ? depth : layers;
    const int channels = scalar ? 1 : format_channels(tex.format);
    std::vector<std::string> names =
        manifest && int(manifest->channel_meanings.size()) == channels ? manifest->channel_meanings : default_channel_names(channels);
    const Box3d bounds = manifest && manifest->world_bounds ? *manifest->world_bounds
                                                            : Box3d{{{0, 0, 0}}, {{double(tex.width), double(tex.height), double(nz)}}};
    Field3D out(Vec3i{{tex.width, tex.height, nz}}, channels, bounds, names);
    for (int layer = 0; layer < layers; ++layer) {
        detail::DecodedLevel L = detail::decode_level(tex, layer, 0, decoder, scalar, unpack);
        const size_t slice = size_t(tex.width) * size_t(tex.height);
        for (int c = 0; c < channels; ++c) {
            auto dst = out.channel(c);
            for (size_t i = 0; i < L.lo[size_t(c)].size(); ++i) // DDS rows top-down -> field rows y-up
                dst[size_t(layer) * slice + detail::dds_row_flip(i, L.w, L.h)] =
                    map.to_src(0.5f * (L.lo[size_t(c)][i] + L.hi[size_t(c)][i]));
        }
    }
    return out;
}

CompressReport verify_texture(const DdsTexture& tex, const TextureManifest* manifest, const Field3D& source, DecoderSet decoders,
                              const std::vector<int>& channels, const std::string& what) {
    const int nz = tex.volume ? tex.depth : tex.array_size;
    if (source.nx() != tex.width || source.ny() != tex.height || source.nz() != nz)
        throw Error(what + ": texture is " + std::to_string(tex.width) + "x" + std::to_string(tex.height) + "x" +
                    std::to_string(nz) + " but the source field is " + std::to_string(source.nx()) + "x" + std::to_string(source.ny()) +
                    "x" + std::to_string(source.nz()));
    const bool scalar = manifest && manifest->encoding == "bc1-scalar";
    CompressReport r;
    r.file = what;
    r.format = manifest ? manifest->encoding : dxgi_format_name(tex.format);
    r.width = tex.width;
    r.height = tex.height;
    r.depth = tex.depth;
    r.array_size = tex.array_size;
    r.mip_levels = tex.mip_levels;
    r.channels = scalar ? 1 : format_channels(tex.format);
    r.texels = uint64_t(tex.width) * uint64_t(tex.height) * uint64_t(nz);
    r.bytes = tex.data.size();
    if (manifest) {
        r.value_range = {manifest->range_lo, manifest->range_hi};
        r.requested_max_error = manifest->max_error;
        r.one_sided_below = manifest->one_sided_below;
    }
    ScalarUnpack unpack;
    if (scalar) unpack.weights = manifest->unpack_weights;
    detail::Mapping map;
    map.kind = detail::map_kind(tex.format);
    if (manifest) {
        map.lo = manifest->range_lo;
        map.hi = manifest->range_hi;
    } else
        map.kind = detail::MapKind::Float;
    auto src_channel = [&](int c) -> int {
        if (!channels.empty()) return c < int(channels.size()) ? channels[size_t(c)] : -1;
        return c < source.channels() ? c : -1;
    };
    const size_t slice = size_t(tex.width) * size_t(tex.height);
    // Each decoder model is decoded and measured by one task (its sums run in a
    // fixed order), so the report does not depend on the thread count; the
    // models are independent, which keeps both cores busy on a large volume.
    struct ModelResult {
        DecoderStats st;
        std::vector<double> sq;
    };
    const std::vector<Decoder> models = decoders_in(decoders);
    std::vector<ModelResult> results(models.size());
    parallel_for_each(models.size(), 1, [&](size_t k) {
        const Decoder d = models[k];
        DecoderStats& st = results[k].st;
        std::vector<double>& sq = results[k].sq;
        st.decoder = d;
        st.max_error.assign(size_t(r.channels), 0.0);
        st.max_over = -INFINITY;
        double under = 0;
        uint64_t count = 0;
        sq.assign(size_t(r.channels), 0.0);
        const int depth0 = tex.level_depth(0);
        constexpr int kSlabSlices = 4;
        for (int layer = 0; layer < tex.array_size; ++layer) {
            for (int z0 = 0; z0 < depth0; z0 += kSlabSlices) {
                const int z1 = std::min(depth0, z0 + kSlabSlices);
                detail::DecodedLevel L = detail::decode_level(tex, layer, 0, d, scalar, unpack, z0, z1);
                const size_t first = (size_t(layer) * size_t(depth0) + size_t(z0)) * slice;
                for (int c = 0; c < r.channels; ++c) {
                    const int sc = src_channel(c);
                    const float missing = map.to_src(c == 3 ? 1.0f : 0.0f); // a missing channel: stored constants
                    const float* src = sc >= 0 ? source.channel(sc).data() + first : nullptr;
                    const float* dlo = L.lo[size_t(c)].data();
                    const float* dhi = L.hi[size_t(c)].data();
                    const size_t W = size_t(L.w), rows = L.lo[size_t(c)].size() / W;
                    double max_error = st.max_error[size_t(c)], max_over = st.max_over, sum_sq = sq[size_t(c)];
                    uint64_t violations = st.one_sided_violations;
                    // Row by row, in the decoded slab's order (so the sums add in the same
                    // order as texel by texel): DDS rows run top-down, the source is y-up.
                    for (size_t row = 0; row < rows; ++row) {
                        const size_t i0 = row * W;
                        const float* srow = src ? src + detail::dds_row_flip(i0, L.w, L.h) : nullptr;
                        for (size_t x = 0; x < W; ++x) {
                            const float s = srow ? srow[x] : missing;
                            // In double, as an engine may reconstruct: the float mapping can round
                            // an ulp below and hide a texel just above its source.
                            const double lo = map.to_src_exact(dlo[i0 + x]), hi = map.to_src_exact(dhi[i0 + x]);
                            max_error = std::max(max_error, std::max(hi - s, s - lo));
                            max_over = std::max(max_over, hi - s);
                            violations += hi > s ? 1 : 0;
                            const double mid = map.to_src_exact(0.5 * (double(dlo[i0 + x]) + double(dhi[i0 + x])));
                            under += s - mid;
                            sum_sq += (mid - s) * (mid - s);
                        }
                    }
                    st.max_error[size_t(c)] = max_error;
                    st.max_over = max_over;
                    st.one_sided_violations = violations;
                    sq[size_t(c)] = sum_sq;
                    count += rows * W;
                }
            }
        }
        st.mean_under = count ? under / double(count) : 0;
    });
    for (ModelResult& m : results) {
        DecoderStats& st = m.st;
        if (st.decoder == Decoder::Reference || r.max_error.empty()) {
            r.max_error = st.max_error;
            r.rmse.assign(size_t(r.channels), 0.0);
            r.psnr.assign(size_t(r.channels), 0.0);
            // PSNR peak: the mapped range, or for identity-mapped (float) formats the
            // data range the manifest records (1 without a manifest).
            const double span = double(map.hi) - map.lo;
            const double range = span > 0 ? span : 1.0;
            for (int c = 0; c < r.channels; ++c) {
                r.rmse[size_t(c)] = std::sqrt(m.sq[size_t(c)] / double(r.texels));
                r.psnr[size_t(c)] = r.rmse[size_t(c)] > 0 ? 20.0 * std::log10(range / r.rmse[size_t(c)]) : INFINITY;
            }
        }
        for (double e : st.max_error) r.bound_max_error = std::max(r.bound_max_error, e);
        r.per_decoder.push_back(std::move(st));
    }
    return r;
}

} // namespace atlas::compress
