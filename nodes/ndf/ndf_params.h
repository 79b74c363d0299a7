// Shared by the ndf nodes (not a node): the 2D map grid parameters.
#pragma once

#include "atlas/graph/node.h"
#include "common/grid.h"

#include <string>

namespace atlas::ndf_nodes {

// resolution / bounds_min / bounds_max of a generated map (nodes/common/grid.h);
// defaults: the HZD weather map, 60 km x 60 km at 512 x 512 texels.
inline void declare_map(NodeDeclaration& d) { grid_nodes::declare_map(d, grid_nodes::kWeatherMap); }
using grid_nodes::map_bounds;

inline Vec2i map_resolution(const CookContext& ctx, int channels = 1) {
    const Vec2i r = ctx.get_int2("resolution");
    ctx.check_memory(field_bytes(uint64_t(r[0]) * uint64_t(r[1]), channels), "the map");
    return r;
}

inline Value out2d(Field2D f) { return Field2DPtr(std::make_shared<const Field2D>(std::move(f))); }

inline WrapMode wrap_mode(const CookContext& ctx) { return ctx.get_bool("tileable") ? WrapMode::Wrap : WrapMode::Clamp; }

// The channel a string parameter names, by name or by index.
inline int channel_param(const CookContext& ctx, const Field2D& f, const std::string& param) {
    const std::string& name = ctx.get_string(param);
    int c = f.find_channel(name);
    if (c >= 0) return c;
    try {
        size_t used = 0;
        c = std::stoi(name, &used);
        if (used != name.size()) c = -1;
    } catch (const std::exception&) {
        ctx.fail("'" + param + "': no channel named '" + name + "'");
    }
    if (c < 0 || c >= f.channels()) ctx.fail("'" + param + "': no channel named '" + name + "' and no channel index " + name);
    return c;
}

} // namespace atlas::ndf_nodes
