// Shared by the noise nodes (not a node): the parameters every noise node
// has, and the cook that turns them into a NoiseSpec and calls fill_noise.
#pragma once

#include "atlas/graph/node.h"
#include "common/grid.h"
#include "atlas/noise/fill.h"
#include "atlas/noise/loop.h"

#include <string>
#include <type_traits>

namespace atlas::noise_nodes {

inline void declare_common(NodeDeclaration& d, Vec3i period = {{4, 4, 4}}) {
    // Tiles: each window is filled on its own (cook_noise), except with
    // normalize, which needs the whole field's min/max: cooked whole and cropped.
    d.tiling(TileRule::pointwise().windowed([](const NodeParams& p) -> std::optional<TileGrid> {
        if (p.get_bool("normalize")) return std::nullopt;
        return grid_nodes::tile_grid(p);
    }));
    d.output("out", PortType::Field, "the noise field (Field3D, or Field2D when dimensions = 2d)");
    d.param_enum("dimensions", {"3d", "2d"}, "3d").describe("Field3D, or Field2D over x, y");
    grid_nodes::declare_grid(d, grid_nodes::kNoiseGrid, "voxels along x, y, z (z unused in 2D)");
    d.param_int3("period", period).range(1, 1 << 30).with_unit("cells").describe("lattice cells per tile along x, y, z (the tiling period)");
    d.param_float("frequency", 1).range(0, 1e6).describe("tiles across the field; an integer keeps the field seamless, 0 gives a constant");
    d.param_float3("offset", {{0, 0, 0}}).with_unit("cells").describe("lattice offset (e.g. for animation)");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("random seed");
    d.param_int("octaves", 1).range(1, 16).describe("fractal octaves; octave k has period * lacunarity^k");
    d.param_int("lacunarity", 2).range(1, 1024).describe("integer frequency ratio between octaves (keeps every period an integer)");
    d.param_float("gain", 0.5).range(0, 4).describe("amplitude ratio between octaves");
    d.param_enum("combinator", {"fbm", "turbulence", "billow", "ridged"}, "fbm").describe("how octaves are summed (docs/noise.md)");
    d.param_bool("invert", false).describe("lo + hi - v over the signal's range");
    d.param_int("fold_count", 0).range(0, 8).describe("Nubis twice-folded trick: t -> |2t - 1| applied this many times");
    d.param_bool("remap", false).describe("map [in_min, in_max] to [out_min, out_max]");
    d.param_float2("in_range", {{0, 1}}).describe("remap source range");
    d.param_float2("out_range", {{0, 1}}).describe("remap target range (also the normalize target)");
    d.param_bool("clamp", true).describe("clamp remapped values to out_range");
    d.param_bool("normalize", false).describe("stretch the measured min..max to out_range (use the full range)");
    d.param_float3("loop_shift", {{0, 0, 0}}).with_unit("cells")
        .describe("a loop in time (docs/noise.md, \"Loops\"): how far the pattern drifts over one loop while it is crossfaded into the next; 0: no loop");
    d.param_float("loop_phase", 0).range(0, 1).describe("where in the loop (key it from 0 to 1 over the loop's time; 0 and 1 give the same field)");
}

// Reads the common parameters into `spec` (kernel-specific fields already
// set), fills a new field and sets "out".
inline void cook_noise(CookContext& ctx, noise::NoiseSpec spec) {
    spec.period = ctx.get_int3("period");
    spec.frequency = ctx.get_float("frequency");
    spec.offset = ctx.get_float3("offset");
    spec.seed = uint32_t(ctx.get_int("seed"));
    spec.fractal.octaves = int(ctx.get_int("octaves"));
    spec.fractal.lacunarity = int(ctx.get_int("lacunarity"));
    spec.fractal.gain = ctx.get_float("gain");
    spec.fractal.combinator = noise::parse_combinator(ctx.get_string("combinator"));
    spec.output.invert = ctx.get_bool("invert");
    spec.output.fold_count = int(ctx.get_int("fold_count"));
    spec.output.remap = ctx.get_bool("remap");
    const Vec2d in = ctx.get_float2("in_range"), out = ctx.get_float2("out_range");
    spec.output.in_min = in[0];
    spec.output.in_max = in[1];
    spec.output.out_min = out[0];
    spec.output.out_max = out[1];
    spec.output.clamp = ctx.get_bool("clamp");
    spec.output.normalize = ctx.get_bool("normalize");
    const Vec3d lo = ctx.get_float3("bounds_min"), hi = ctx.get_float3("bounds_max");
    const Vec3i res = ctx.get_int3("resolution");
    const bool two_d = ctx.get_string("dimensions") == "2d";
    // Library errors need no wrapping: the evaluator prefixes them with the node.
    spec.validate(two_d ? 2 : 3);
    const int comps = noise::noise_components(spec.kernel, two_d ? 2 : 3);
    // A loop in time (atlas/noise/loop.h): this field shifted by phase * D, crossfaded
    // into the one shifted by (phase - 1) * D; phase 0 and 1 are the unshifted field.
    const Vec3d shift = ctx.get_float3("loop_shift");
    const double phase = ctx.get_float("loop_phase");
    const bool looped = (shift[0] != 0 || shift[1] != 0 || shift[2] != 0) && phase > 0 && phase < 1;
    noise::NoiseSpec next = spec;
    if (looped)
        for (int a = 0; a < 3; ++a) {
            spec.offset[a] += phase * shift[a];
            next.offset[a] += (phase - 1) * shift[a];
        }
    // A tiled cook's window of the grid (docs/scale.md), else the whole grid.
    const TileWindow* w = ctx.window();
    const noise::FillWindow fw = w ? noise::FillWindow{w->x0, w->y0, res[0], res[1]} : noise::FillWindow{0, 0, res[0], res[1]};
    const Vec2i wres = w ? w->size() : Vec2i{{res[0], res[1]}};
    // Fills f (the field shifted by phase * D) and, looping, crossfades the next one into it.
    auto fill = [&](auto& f) {
        noise::fill_noise(f, 0, spec, &ctx.progress_sink(), &fw);
        if (!looped) return;
        std::decay_t<decltype(f)> g(f.resolution(), comps, f.bounds(), f.channel_names(), &ctx.budget());
        noise::fill_noise(g, 0, next, nullptr, &fw);
        for (int c = 0; c < comps; ++c) noise::loop_crossfade(f.channel(c), g.channel(c), phase);
    };
    if (two_d) {
        Box2d box{{{lo[0], lo[1]}}, {{hi[0], hi[1]}}};
        if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in x and y");
        auto f = ctx.make_field2d(wres, comps, w ? w->bounds() : box);
        fill(*f);
        ctx.set_output("out", Field2DPtr(f));
    } else {
        Box3d box{lo, hi};
        if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
        if (w) box = {{{w->bounds().min[0], w->bounds().min[1], lo[2]}}, {{w->bounds().max[0], w->bounds().max[1], hi[2]}}};
        auto f = ctx.make_field3d({{wres[0], wres[1], res[2]}}, comps, box);
        fill(*f);
        ctx.set_output("out", Field3DPtr(f));
    }
}

} // namespace atlas::noise_nodes
