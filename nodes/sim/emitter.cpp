// sim/emitter: heat and vapour source rates for sim/cloud_growth, from a
// noise-modulated ground patch or from any Field3D mask (shapes, meshes, noise).
#include "atlas/noise/value_fbm.h"
#include "sim_params.h"
#include "volume/grid_params.h"

#include <algorithm>
#include <cmath>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a solver forcing on a grid of its own, read whole by sim/cloud_growth"));
    d.doc("Heat (K/s) and vapour (kg/kg/s) source rates for sim/cloud_growth's 'emitter' input. 'ground_patch': a disc of "
          "'radius' at 'center' on the grid floor, strength cos^2(pi r / 2R) (1 - h / depth) with h the height above "
          "bounds_min z; 'mask': the input field's channel (negative values count as 0) times the rates, on the mask's grid. "
          "Both are multiplied by (1 - a + 2 a n), n = smooth value noise of feature size noise_scale (2D for the patch, "
          "3D for a mask), a = noise_amount: deterministic for a seed. NaN/Inf in the mask is an error naming the node.");
    d.input("mask", PortType::Field3D, "emitter shape (mode 'mask'): density-like, 0 = no source").optional = true;
    d.output("out", PortType::Field3D, "channels 'heat' (K/s) and 'vapour' (kg/kg/s)");
    d.param_enum("mode", {"ground_patch", "mask"}, "ground_patch").describe("where the sources come from");
    volume_nodes::declare_grid(d, grid_nodes::kCoarseCloudscapeGrid);
    d.param_float2("center", {{2048, 2048}}).with_unit("m").describe("ground_patch: world x, y of the disc centre");
    d.param_float("radius", 500).range(1e-3, 1e9).with_unit("m").describe("ground_patch: disc radius");
    d.param_float("depth", 200).range(1e-3, 1e9).with_unit("m").describe("ground_patch: heated layer depth above the floor");
    d.param_int("channel", 0).range(0, 255).describe("mask: channel of the input used as the shape");
    d.param_float("heat_rate", 0.02).range(-10, 10).with_unit("K/s").describe("potential-temperature source where the shape is 1 (< 0: a cooling emitter, e.g. evaporative or radiative cooling)");
    d.param_float("vapour_rate", 1e-6).range(0, 1e-3).with_unit("kg/kg/s").describe("water-vapour source where the shape is 1");
    d.param_float("noise_scale", 200).range(1e-3, 1e9).with_unit("m").describe("feature size of the modulation noise");
    d.param_float("noise_amount", 0.5).range(0, 1).describe("0 = smooth, 1 = fully noise-modulated");
    d.param_int("seed", 1).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    const double heat = ctx.get_float("heat_rate"), vap = ctx.get_float("vapour_rate");
    const double amount = ctx.get_float("noise_amount"), scale = ctx.get_float("noise_scale");
    const uint32_t seed = uint32_t(ctx.get_int("seed"));
    const bool patch = ctx.get_string("mode") == "ground_patch";
    Field3DPtr mask;
    Vec3i res;
    Box3d box;
    int ch = 0;
    if (patch) {
        res = ctx.get_int3("resolution");
        box = volume_nodes::grid_bounds(ctx);
    } else {
        if (!ctx.has_input("mask")) ctx.fail("mode 'mask' needs the 'mask' input connected");
        mask = ctx.input_field3d("mask");
        ch = int(ctx.get_int("channel"));
        if (ch >= mask->channels())
            ctx.fail("parameter 'channel' is " + std::to_string(ch) + " but the mask has " + std::to_string(mask->channels()) + " channel(s)");
        for (float v : mask->channel(ch))
            if (!std::isfinite(v)) ctx.fail("input 'mask' holds NaN/Inf; emitter shapes must be finite");
        res = mask->resolution();
        box = mask->bounds();
    }
    auto out = ctx.make_field3d(res, 2, box, {"heat", "vapour"});
    const Vec2d c = ctx.get_float2("center");
    const double radius = ctx.get_float("radius"), depth = ctx.get_float("depth");
    for (int z = 0; z < res[2]; ++z) {
        ctx.progress(double(z) / res[2]);
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const Vec3d p = out->voxel_center(x, y, z);
                double shape = 0, n = 0;
                if (patch) {
                    const double r = std::hypot(p[0] - c[0], p[1] - c[1]) / radius;
                    const double h = p[2] - box.min[2];
                    if (r >= 1 || h > depth) continue;
                    shape = std::pow(std::cos(0.5 * M_PI * r), 2) * (1 - h / depth);
                    n = noise::smooth_value_noise(seed, p[0] / scale, p[1] / scale, 0.0);
                } else {
                    shape = std::max(0.0f, mask->at(ch, x, y, z));
                    if (shape == 0) continue;
                    n = noise::smooth_value_noise(seed, p[0] / scale, p[1] / scale, p[2] / scale);
                }
                const double m = shape * ((1 - amount) + amount * 2 * n);
                out->at(0, x, y, z) = float(heat * m);
                out->at(1, x, y, z) = float(vap * m);
            }
    }
    ctx.set_output("out", Field3DPtr(std::move(out)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "sim/emitter", .version = 2, .declare = declare, .cook = cook});
}
