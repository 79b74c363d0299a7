// Shared by every node that makes a field on a world grid (not a node): the grid
// parameters resolution / bounds_min / bounds_max, declared and read in one place.
// Node families keep their own defaults, each named here, so a changed default is
// one visible line (docs/architecture.md, "Option schemas").
#pragma once

#include "atlas/graph/node.h"

namespace atlas::grid_nodes {

struct GridDefaults {
    Vec3i resolution;
    Vec3d bounds_min, bounds_max;
};
struct MapDefaults {
    Vec2i resolution;
    Vec2d bounds_min, bounds_max;
};

// The volume nodes: the Nubis cloudscape, 4 km x 4 km x 512 m at 8 m voxels.
inline const GridDefaults kCloudscapeGrid{{{512, 512, 64}}, {{0, 0, 0}}, {{4096, 4096, 512}}};
// field/constant, noise/value, sim/emitter: the same box at 64 m voxels (quick to cook).
inline const GridDefaults kCoarseCloudscapeGrid{{{64, 64, 16}}, {{0, 0, 0}}, {{4096, 4096, 512}}};
// The noise nodes: a unit cube at 128^3 (their tiles are counted in cells, not metres).
inline const GridDefaults kNoiseGrid{{{128, 128, 128}}, {{0, 0, 0}}, {{1, 1, 1}}};
// The ndf map nodes: the HZD weather map, 60 km x 60 km at 512 x 512 texels.
inline const MapDefaults kWeatherMap{{{512, 512}}, {{0, 0}}, {{60000, 60000}}};
// import/image: a 4 km square (the resolution is the image's).
inline const MapDefaults kCloudscapeMap{{{1, 1}}, {{0, 0}}, {{4096, 4096}}};

constexpr double kMaxGridResolution = 65536;

// bounds_min / bounds_max (for nodes whose resolution comes from a file).
inline void declare_bounds(NodeDeclaration& d, Vec3d lo, Vec3d hi) {
    d.param_float3("bounds_min", lo).with_unit("m").describe("world-space minimum corner");
    d.param_float3("bounds_max", hi).with_unit("m").describe("world-space maximum corner");
}
inline void declare_map_bounds(NodeDeclaration& d, Vec2d lo, Vec2d hi) {
    d.param_float2("bounds_min", lo).with_unit("m").describe("world-space minimum corner");
    d.param_float2("bounds_max", hi).with_unit("m").describe("world-space maximum corner");
}

// resolution (1..65536 voxels per axis), then the bounds.
inline void declare_grid(NodeDeclaration& d, const GridDefaults& g, const char* resolution_doc = "voxels along x, y, z") {
    d.param_int3("resolution", g.resolution).range(1, kMaxGridResolution).with_unit("voxels").describe(resolution_doc).follows_proxy(ProxyScale::Cells);
    declare_bounds(d, g.bounds_min, g.bounds_max);
}
inline void declare_map(NodeDeclaration& d, const MapDefaults& g) {
    d.param_int2("resolution", g.resolution).range(1, kMaxGridResolution).with_unit("texels").describe("texels along x, y").follows_proxy(ProxyScale::Cells);
    declare_map_bounds(d, g.bounds_min, g.bounds_max);
}

// The XY grid a node with declare_grid's parameters makes: what a windowed
// generator's TileRule returns (TileRule::windowed).
inline TileGrid tile_grid(const NodeParams& p) {
    const Vec3i r = p.get_int3("resolution");
    const Vec3d lo = p.get_float3("bounds_min"), hi = p.get_float3("bounds_max");
    return TileGrid{{{r[0], r[1]}}, Box2d{{{lo[0], lo[1]}}, {{hi[0], hi[1]}}}};
}

// The declared bounds; fails naming the node when they are empty in some axis.
inline Box3d grid_bounds(const CookContext& ctx) {
    Box3d box{ctx.get_float3("bounds_min"), ctx.get_float3("bounds_max")};
    if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
    return box;
}
inline Box2d map_bounds(const CookContext& ctx) {
    Box2d box{ctx.get_float2("bounds_min"), ctx.get_float2("bounds_max")};
    if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in x and y");
    return box;
}

} // namespace atlas::grid_nodes
