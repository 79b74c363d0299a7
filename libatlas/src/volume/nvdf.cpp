// Dimensional profile, field-data encoding and the NVDF channel set.
#include "atlas/volume/nvdf.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace atlas::volume {
namespace {
void check_channel(const Field3D& f, int c, const char* who) {
    if (c < 0 || c >= f.channels())
        throw Error(std::string(who) + ": channel " + std::to_string(c) + " does not exist (the input has " + std::to_string(f.channels()) +
                    " channel" + (f.channels() == 1 ? "" : "s") + ")");
}
void check_range(double lo, double hi, const char* who) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo))
        throw Error(std::string(who) + ": range_max must be greater than range_min (both finite), got [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "]");
}

// One channel of `src` mapped voxel by voxel into a new single-channel field.
template <typename Map>
Field3D map_channel(const Field3D& src, int channel, const char* out_name, const MemoryBudget* budget, Map map) {
    Field3D out(src.resolution(), 1, src.bounds(), {out_name}, budget);
    auto s = src.channel(channel);
    auto d = out.channel(0);
    for (size_t i = 0; i < s.size(); ++i) d[i] = map(double(s[i]));
    return out;
}
} // namespace

Field3D dimensional_profile(const Field3D& sdf, const DimensionalProfileOptions& o, const MemoryBudget* budget) {
    check_channel(sdf, o.channel, "dimensional_profile");
    if (!(o.depth > 0) || !std::isfinite(o.depth)) throw Error("dimensional_profile: depth must be finite and > 0 metres");
    if (!(o.exponent > 0) || !std::isfinite(o.exponent)) throw Error("dimensional_profile: exponent must be finite and > 0");
    return map_channel(sdf, o.channel, "dimensional_profile", budget, [&o](double v) {
        const double t = std::clamp(-v / o.depth, 0.0, 1.0);
        return float(o.exponent == 1 ? t : std::pow(t, o.exponent));
    });
}

Field3D encode_field_data(const Field3D& sdf, double lo, double hi, int channel, const MemoryBudget* budget) {
    check_channel(sdf, channel, "encode_field_data");
    check_range(lo, hi, "encode_field_data");
    return map_channel(sdf, channel, "field_data", budget, [=](double v) { return float(std::clamp((v - lo) / (hi - lo), 0.0, 1.0)); });
}

Field3D decode_field_data(const Field3D& enc, double lo, double hi, int channel, const MemoryBudget* budget) {
    check_channel(enc, channel, "decode_field_data");
    check_range(lo, hi, "decode_field_data");
    return map_channel(enc, channel, "sdf", budget, [=](double v) { return float(lo + v * (hi - lo)); });
}

Field3D assemble_modeling_nvdf(const Field3D& dp, const Field3D& dt, const Field3D& ds, const MemoryBudget* budget, const ModelingChannels& ch) {
    for (const Field3D* f : {&dt, &ds})
        if (f->resolution() != dp.resolution() || !(f->bounds() == dp.bounds()))
            throw Error("modeling NVDF: detail_type and density_scale must have the dimensional profile's resolution and bounds");
    const Field3D* src[3] = {&dp, &dt, &ds};
    const int sel[3] = {ch.dimensional_profile, ch.detail_type, ch.density_scale};
    const char* names[3] = {"modeling NVDF (dimensional_profile)", "modeling NVDF (detail_type)", "modeling NVDF (density_scale)"};
    for (int c = 0; c < 3; ++c) check_channel(*src[c], sel[c], names[c]);
    Field3D out(dp.resolution(), 3, dp.bounds(), {"dimensional_profile", "detail_type", "density_scale"}, budget);
    for (int c = 0; c < 3; ++c) std::copy(src[c]->channel(sel[c]).begin(), src[c]->channel(sel[c]).end(), out.channel(c).begin());
    return out;
}

Field3D blend_nvdf(const Field3D& a, const Field3D& b, double t, const MemoryBudget* budget) {
    auto grid_text = [](const Field3D& f) {
        const auto r = f.resolution();
        const Box3d& bb = f.bounds();
        char buf[160];
        std::snprintf(buf, sizeof buf, "%dx%dx%d over [%g, %g, %g] - [%g, %g, %g] m", r[0], r[1], r[2], bb.min[0], bb.min[1], bb.min[2], bb.max[0],
                      bb.max[1], bb.max[2]);
        return std::string(buf);
    };
    if (a.resolution() != b.resolution() || !(a.bounds() == b.bounds()))
        throw Error("blend: the two sets must share one grid; a is " + grid_text(a) + ", b is " + grid_text(b) +
                    " (resample one onto the other's grid with volume/transform)");
    if (a.channels() != b.channels()) throw Error("blend: a has " + std::to_string(a.channels()) + " channels, b " + std::to_string(b.channels()));
    for (int c = 0; c < a.channels(); ++c)
        if (a.channel_name(c) != b.channel_name(c))
            throw Error("blend: channel " + std::to_string(c) + " is '" + a.channel_name(c) + "' in a but '" + b.channel_name(c) + "' in b");
    if (!std::isfinite(t)) throw Error("blend: the blend amount must be finite");
    const float u = static_cast<float>(std::clamp(t, 0.0, 1.0));
    std::vector<std::string> names;
    for (int c = 0; c < a.channels(); ++c) names.push_back(a.channel_name(c));
    Field3D out(a.resolution(), a.channels(), a.bounds(), names, budget);
    for (int c = 0; c < a.channels(); ++c) {
        const auto pa = a.channel(c), pb = b.channel(c);
        auto po = out.channel(c);
        if (a.channel_name(c) == "sdf" && u > 0.0f && u < 1.0f) {
            for (size_t i = 0; i < po.size(); ++i) po[i] = std::min(pa[i], pb[i]);
        } else {
            // a (1 - t) + b t: exactly a at 0 and exactly b at 1.
            for (size_t i = 0; i < po.size(); ++i) po[i] = pa[i] * (1.0f - u) + pb[i] * u;
        }
    }
    return out;
}

} // namespace atlas::volume
