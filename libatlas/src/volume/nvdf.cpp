// Dimensional profile, field-data encoding and the NVDF channel set.
#include "atlas/volume/nvdf.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include <algorithm>
#include <cmath>

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

} // namespace atlas::volume
