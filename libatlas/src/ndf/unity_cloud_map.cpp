// Unity HDRP volumetric clouds (manual mode): the cloud map layout.
#include "atlas/ndf/exporters.h"
#include "atlas/ndf/ndf_set.h"

#include "exporters_common.h"
#include "atlas/core/parallel.h"

namespace atlas::ndf {

Field2D unity_cloud_map(const Field2D& set, CloudLayer layer, const MemoryBudget* budget) {
    check_ndf_set(set);
    detail::check_layer(layer, "unity cloud map");
    Field2D out(set.resolution(), 4, set.bounds(), {"r", "g", "b", "a"}, budget);
    const int src[3] = {Coverage, Precipitation, Type};
    for (int c = 0; c < 3; ++c) std::copy(set.channel(src[c]).begin(), set.channel(src[c]).end(), out.channel(c).begin());
    auto mh = set.channel(MaxHeight);
    auto a = out.channel(3);
    parallel_for_each(mh.size(), 4096, [&](size_t i) { a[i] = detail::in_layer(mh[i], layer); });
    return out;
}

} // namespace atlas::ndf
