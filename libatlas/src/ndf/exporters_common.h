// Private: shared by the engine exporters.
#pragma once

#include "atlas/core/error.h"
#include "atlas/ndf/exporters.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace atlas::ndf::detail {

inline void check_layer(CloudLayer layer, const char* who) {
    if (!std::isfinite(layer.bottom) || !std::isfinite(layer.top) || !(layer.top > layer.bottom))
        throw Error(std::string(who) + ": 'layer_top' must be finite and greater than 'layer_bottom'");
}

// A height (m) as a fraction of the layer, clamped to [0, 1]; NaN -> 0.
inline float in_layer(float h, CloudLayer layer) {
    const double v = (double(h) - layer.bottom) / (layer.top - layer.bottom);
    return float(std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0));
}

} // namespace atlas::ndf::detail
