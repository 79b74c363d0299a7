// field/resample: a 3D field onto a new resolution and bounds, trilinearly.
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Trilinear (bilinear for 2D) resampling onto a new resolution; bounds default to the input's. Tiles when it keeps the "
          "input's XY resolution and bounds (z only; keep_bounds, wrap: clamp).");
    d.input("in", PortType::Field, "field to resample");
    // Tiles when it keeps the XY grid (resampling z only): halo 1 texel for the
    // bilinear tap + 1 for rounding, or the whole grid with wrap: wrap (its taps read
    // around the world, not the tile); any other XY resolution changes the grid.
    d.tiling(TileRule::with_grid_halo([](const NodeParams& p, const TileGrid& g) { return p.get_string("wrap") == "wrap" ? std::max(g.res[0], g.res[1]) : 2; },
                                      [](const NodeParams& p) -> std::string {
                                          if (!p.get_bool("keep_bounds")) return "keep_bounds: false changes the grid (tiles are regions of one grid)";
                                          return "";
                                      })
                 .with_window());
    d.output("out", PortType::Field, "resampled field, same dimensionality");
    d.param_int3("resolution", {{64, 64, 16}}).range(1, 65536).with_unit("voxels").describe("new resolution (z ignored for 2D)").follows_proxy(ProxyScale::Cells);
    d.param_bool("keep_bounds", true).describe("keep the input's world bounds (else use bounds_min/bounds_max)");
    d.param_float3("bounds_min", {{0, 0, 0}}).with_unit("m").describe("new minimum corner when keep_bounds is false");
    d.param_float3("bounds_max", {{1, 1, 1}}).with_unit("m").describe("new maximum corner when keep_bounds is false");
    d.param_enum("wrap", {"clamp", "wrap"}, "clamp").describe("outside the source: repeat the edge (clamp) or tile (wrap)");
}

// Field3D::sample_voxel's taps (the same operations), for coordinate u of a
// grid of n voxels, read from a window starting at `origin` of `local` voxels.
struct Taps {
    int i0, i1;
    float t;
};
Taps taps(double u, int n, int origin, int local) {
    double f = u - 0.5;
    if (!std::isfinite(f)) f = 0.0;
    double fl = std::floor(f);
    const float t = float(f - fl);
    if (fl > 1e9) fl = 1e9;
    if (fl < -1e9) fl = -1e9;
    const int base = int(fl);
    auto fix = [&](int i) { return std::clamp(std::clamp(i, 0, n - 1) - origin, 0, local - 1); };
    return {fix(base), fix(base + 1), t};
}

// A tiled cook: `in` is a crop (window `w`) of the whole grid, and the output
// keeps the XY grid. resample_field's arithmetic with the whole grid's
// coordinates (clamped reads beyond the crop only reach halo texels, whose
// results the tiled cook discards).
Value resample_window(CookContext& ctx, const TileWindow& win, Vec3i res) {
    const Vec2i g = win.grid.res;
    if (res[0] != g[0] || res[1] != g[1])
        ctx.fail("a tiled cook needs the XY resolution kept (" + std::to_string(g[0]) + " x " + std::to_string(g[1]) + "), got " +
                 std::to_string(res[0]) + " x " + std::to_string(res[1]) + ": resample z only, or cook untiled");
    const Box2d& gb = win.grid.bounds;
    const double sx = gb.size()[0] / g[0], sy = gb.size()[1] / g[1]; // source = output texel size (same grid)
    const double ux_lo = gb.min[0], uy_lo = gb.min[1];
    auto coord = [&](int i, double lo, double s) { return ((lo + (i + 0.5) * s) - lo) / s; };
    if (auto f3 = std::get_if<Field3DPtr>(&ctx.input("in"))) {
        const Field3D& src = **f3;
        const int w = src.nx(), h = src.ny();
        ctx.check_memory(field_bytes(uint64_t(w) * h * res[2], src.channels()), "the resampled field");
        auto out = std::make_shared<Field3D>(Vec3i{{w, h, res[2]}}, src.channels(), src.bounds(), src.channel_names(), &ctx.budget());
        const double lz = src.bounds().min[2], szo = src.bounds().size()[2] / res[2], szs = src.voxel_size()[2];
        parallel_for_index(res[2], [&](int z) {
            const Taps tz = taps(((lz + (z + 0.5) * szo) - lz) / szs, src.nz(), 0, src.nz());
            for (int y = 0; y < h; ++y) {
                const Taps ty = taps(coord(win.y0 + y, uy_lo, sy), g[1], win.y0, h);
                for (int x = 0; x < w; ++x) {
                    const Taps tx = taps(coord(win.x0 + x, ux_lo, sx), g[0], win.x0, w);
                    for (int c = 0; c < src.channels(); ++c) {
                        auto ch = src.channel(c);
                        auto row = [&](int yy, int zz) { return atlas::lerp(ch[src.index(tx.i0, yy, zz)], ch[src.index(tx.i1, yy, zz)], tx.t); };
                        const float a = atlas::lerp(row(ty.i0, tz.i0), row(ty.i1, tz.i0), ty.t);
                        const float b = atlas::lerp(row(ty.i0, tz.i1), row(ty.i1, tz.i1), ty.t);
                        out->at(c, x, y, z) = atlas::lerp(a, b, tz.t);
                    }
                }
            }
        });
        return Field3DPtr(out);
    }
    auto src = ctx.input_field2d("in");
    const int w = src->width(), h = src->height();
    auto out = std::make_shared<Field2D>(Vec2i{{w, h}}, src->channels(), src->bounds(), src->channel_names(), &ctx.budget());
    parallel_for_index(h, [&](int y) {
        const Taps ty = taps(coord(win.y0 + y, uy_lo, sy), g[1], win.y0, h);
        for (int x = 0; x < w; ++x) {
            const Taps tx = taps(coord(win.x0 + x, ux_lo, sx), g[0], win.x0, w);
            for (int c = 0; c < src->channels(); ++c) {
                auto ch = src->channel(c);
                const float a = atlas::lerp(ch[src->index(tx.i0, ty.i0)], ch[src->index(tx.i1, ty.i0)], tx.t);
                const float b = atlas::lerp(ch[src->index(tx.i0, ty.i1)], ch[src->index(tx.i1, ty.i1)], tx.t);
                out->at(c, x, y) = atlas::lerp(a, b, ty.t);
            }
        }
    });
    return Field2DPtr(out);
}

void cook(CookContext& ctx) {
    if (const TileWindow* win = ctx.window()) {
        ctx.set_output("out", resample_window(ctx, *win, ctx.get_int3("resolution")));
        return;
    }
    const WrapMode wrap = ctx.get_string("wrap") == "wrap" ? WrapMode::Wrap : WrapMode::Clamp;
    const Vec3i res = ctx.get_int3("resolution");
    const Vec3d lo = ctx.get_float3("bounds_min"), hi = ctx.get_float3("bounds_max");
    const bool keep = ctx.get_bool("keep_bounds");
    if (auto f3 = std::get_if<Field3DPtr>(&ctx.input("in"))) {
        Box3d b = keep ? (*f3)->bounds() : Box3d{lo, hi};
        if (!b.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
        ctx.check_memory(field_bytes(uint64_t(res[0]) * res[1] * res[2], (*f3)->channels()), "the resampled field");
        ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(resample_field(**f3, res, b, wrap, &ctx.budget()))));
    } else {
        auto f2 = ctx.input_field2d("in");
        Box2d b = keep ? f2->bounds() : Box2d{{{lo[0], lo[1]}}, {{hi[0], hi[1]}}};
        if (!b.valid()) ctx.fail("bounds_max must be greater than bounds_min in x and y");
        ctx.set_output("out", Field2DPtr(std::make_shared<Field2D>(resample_field(*f2, {{res[0], res[1]}}, b, wrap, &ctx.budget()))));
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "field/resample", .version = 1, .declare = declare, .cook = cook});
}
