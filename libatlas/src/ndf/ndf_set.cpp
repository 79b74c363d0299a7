// The NDF set layout and the HZD precipitation rule.
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::ndf {

const std::array<std::string, ChannelCount>& ndf_channel_names() {
    static const std::array<std::string, ChannelCount> names{"coverage",   "type",       "top_type",      "bottom_type",
                                                             "min_height", "max_height", "precipitation", "superstorm_coverage"};
    return names;
}

double smoothstep(double e0, double e1, double x) {
    if (e0 == e1) return x < e0 ? 0.0 : 1.0;
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return std::isnan(t) ? 0.0 : t * t * (3.0 - 2.0 * t);
}

Field2D make_ndf_set(Vec2i res, Box2d bounds, double min_height, double max_height, const MemoryBudget* budget) {
    if (!std::isfinite(min_height) || !std::isfinite(max_height)) throw Error("ndf set: 'min_height' and 'max_height' must be finite");
    if (min_height > max_height) throw Error("ndf set: 'min_height' must not be above 'max_height'");
    if (!bounds.valid()) throw Error("ndf set: bounds must be finite with max > min");
    const auto& n = ndf_channel_names();
    Field2D f(res, ChannelCount, bounds, std::vector<std::string>(n.begin(), n.end()), budget);
    std::fill(f.channel(MinHeight).begin(), f.channel(MinHeight).end(), float(min_height));
    std::fill(f.channel(MaxHeight).begin(), f.channel(MaxHeight).end(), float(max_height));
    return f;
}

void check_ndf_set(const Field2D& f) {
    const auto& n = ndf_channel_names();
    if (f.channel_names() != std::vector<std::string>(n.begin(), n.end()))
        throw Error("expected an NDF set (channels coverage, type, top_type, bottom_type, min_height, max_height, precipitation, "
                    "superstorm_coverage); make one with ndf/set");
}

Field2D apply_precipitation_rule(const Field2D& set, const PrecipitationRule& rule, const MemoryBudget* budget) {
    check_ndf_set(set);
    if (!std::isfinite(rule.rain_start) || !std::isfinite(rule.rain_full) || !(rule.rain_full > rule.rain_start))
        throw Error("precipitation rule: 'rain_full' must be greater than 'rain_start' (both finite)");
    if (!(rule.min_coverage >= 0 && rule.min_coverage <= 1)) throw Error("precipitation rule: 'min_coverage' must be in [0, 1]");
    if (!(rule.storm_type >= 0 && rule.storm_type <= 1)) throw Error("precipitation rule: 'storm_type' must be in [0, 1]");
    if (budget) budget->check(set.byte_size(), "the precipitation rule's copy of the NDF set");
    Field2D out = set;
    auto cov = out.channel(Coverage);
    auto type = out.channel(Type);
    auto top = out.channel(TopType);
    auto rain = set.channel(Precipitation);
    parallel_for_each(cov.size(), 4096, [&](size_t i) {
        const double w = smoothstep(rule.rain_start, rule.rain_full, rain[i]);
        if (w <= 0) return;
        type[i] = float(lerp(double(type[i]), rule.storm_type, w));
        top[i] = float(lerp(double(top[i]), rule.storm_type, w));
        cov[i] = float(lerp(double(cov[i]), std::max(double(cov[i]), rule.min_coverage), w));
    });
    return out;
}

} // namespace atlas::ndf
