// volume/metaballs: density from spheres given as parameters and/or points with per-point radius.
#include "atlas/volume/splat.h"
#include "grid_params.h"
#include "spheres_param.h"

#include <cstdio>


namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Metaballs, spheres or particle splats: each sphere (from `spheres` and/or the `points` input, radius from the "
          "points' 'radius' attribute) adds a kernel into a density grid. Kernels: metaball (1-s^2)^3, sphere (solid, "
          "one-voxel edge), linear 1-s, gaussian exp(-4.5 s^2); s = distance / radius. The visible size: a lone ball's 0.5 "
          "surface (what volume/sdf iso 0.5 and the preview draw) lies at 0.45 of the radius for metaball, 1.0 for sphere, "
          "0.5 for linear and 0.39 for gaussian; overlapping balls with blend add grow past it. For clouds of a given "
          "size use sphere, or a metaball radius 2.2 times the size wanted.");
    d.input("points", PortType::Points, "optional sphere centres; attributes 'radius' (m) and 'weight'").optional = true;
    d.output("out", PortType::Field3D, "density, channel 'density'");
    // A world-space source: each tile splats the spheres that reach its window (the points are passed whole).
    d.tiling(TileRule::pointwise().windowed([](const NodeParams& p) -> std::optional<TileGrid> { return grid_nodes::tile_grid(p); })
                 .whole_input("points"));
    volume_nodes::declare_grid(d);
    volume_nodes::declare_spheres(d);
    d.param_enum("kernel", {"metaball", "sphere", "linear", "gaussian"}, "metaball").describe("falloff of each sphere");
    d.param_enum("blend", {"add", "max"}, "add").describe("how overlapping spheres combine");
    d.param_float("default_radius", 64).range(1e-6, 1e9).with_unit("m").describe("radius of points without a 'radius' attribute");
    d.param_float("radius_scale", 1).range(1e-6, 1e6).describe("multiplies every radius");
    d.param_float("weight", 1).range(-1e6, 1e6).describe("multiplies every kernel");
}

void cook(CookContext& ctx) {
    const Vec3i res = ctx.get_int3("resolution");
    const Box3d box = volume_nodes::grid_bounds(ctx);
    std::optional<XYWindow> window; // a tiled cook's part of the grid
    if (const TileWindow* w = ctx.window()) window = XYWindow{w->x0, w->y0, w->x1, w->y1};
    volume_nodes::check_grid_memory(ctx, window ? Vec3i{{window->x1 - window->x0, window->y1 - window->y0, res[2]}} : res, 1);
    Points pts;
    if (ctx.has_input("points")) pts = *ctx.input_points("points");
    std::vector<float> radius = pts.attributes.count("radius") ? pts.attributes["radius"]
                                                               : std::vector<float>(pts.positions.size(), float(ctx.get_float("default_radius")));
    volume_nodes::append_spheres(ctx, pts, radius);
    pts.attributes["radius"] = std::move(radius);
    volume::SplatOptions o;
    o.kernel = volume::parse_splat_kernel(ctx.get_string("kernel"));
    o.blend = volume::parse_splat_blend(ctx.get_string("blend"));
    o.default_radius = ctx.get_float("default_radius");
    o.radius_scale = ctx.get_float("radius_scale");
    o.weight = ctx.get_float("weight");
    ctx.metric("spheres", double(pts.positions.size()));
    // Spheres that miss the grid add nothing; cut ones are clipped clouds.
    size_t outside = 0, cut = 0;
    std::string first_cut;
    for (size_t i = 0; i < pts.positions.size(); ++i) {
        const double r = double(pts.attributes["radius"][i]) * o.radius_scale;
        bool misses = false, crosses = false;
        for (int a = 0; a < 3; ++a) {
            const double c = pts.positions[i][a];
            misses = misses || c + r <= box.min[a] || c - r >= box.max[a];
            crosses = crosses || c - r < box.min[a] || c + r > box.max[a];
        }
        outside += misses;
        if (!misses && crosses && cut++ == 0) {
            char b[128];
            std::snprintf(b, sizeof b, " (the first: %g %g %g radius %g)", pts.positions[i][0], pts.positions[i][1], pts.positions[i][2], r);
            first_cut = b;
        }
    }
    auto where = [&] {
        char b[160];
        std::snprintf(b, sizeof b, "the grid [%g, %g, %g] - [%g, %g, %g] m", box.min[0], box.min[1], box.min[2], box.max[0], box.max[1], box.max[2]);
        return std::string(b);
    };
    if (!pts.positions.empty() && outside == pts.positions.size())
        ctx.fail("every sphere lies outside " + where() + ": check 'spheres' (or the points) against 'bounds_min' and 'bounds_max'");
    if (outside) ctx.warn(std::to_string(outside) + " of " + std::to_string(pts.positions.size()) + " spheres lie outside " + where() + " and add nothing");
    if (cut) ctx.warn(std::to_string(cut) + " spheres cross the faces of " + where() + first_cut + ": the cloud is cut there ('bounds_min', 'bounds_max')");
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::splat_points(pts, res, box, o, &ctx.budget(), window ? &*window : nullptr))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/metaballs", .version = 1, .declare = declare, .cook = cook});
}
