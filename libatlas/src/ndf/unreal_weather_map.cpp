// Unreal Engine volumetric cloud: Atlas's documented weather-map layout.
#include "atlas/ndf/exporters.h"
#include "atlas/ndf/ndf_set.h"

#include "exporters_common.h"
#include "atlas/core/parallel.h"

namespace atlas::ndf {

Field2D unreal_weather_map(const Field2D& set, CloudLayer layer, const MemoryBudget* budget) {
    check_ndf_set(set);
    detail::check_layer(layer, "unreal weather map");
    Field2D out(set.resolution(), 4, set.bounds(), {"r", "g", "b", "a"}, budget);
    std::copy(set.channel(Coverage).begin(), set.channel(Coverage).end(), out.channel(0).begin());
    std::copy(set.channel(Type).begin(), set.channel(Type).end(), out.channel(1).begin());
    auto lo = set.channel(MinHeight), hi = set.channel(MaxHeight);
    auto b = out.channel(2), a = out.channel(3);
    parallel_for_each(lo.size(), 4096, [&](size_t i) {
        b[i] = detail::in_layer(lo[i], layer);
        a[i] = detail::in_layer(hi[i], layer);
    });
    return out;
}

} // namespace atlas::ndf
