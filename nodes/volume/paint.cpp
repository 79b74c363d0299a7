// volume/paint: a channel painted by a height gradient, a shape and noise (detail type, density scale).
#include "atlas/noise/value_noise.h"
#include "atlas/volume/shapes.h"
#include "atlas/graph/node.h"

#include <algorithm>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Paints a 0..1 channel on the grid of `like`: a height gradient from `bottom` (at z_min) to `top` (at z_max), "
          "blended towards `shape_value` inside a sphere/box/capsule (soft edge), plus `noise_amount` x (value noise - 0.5). "
          "Use it for detail_type and density_scale.");
    d.input("like", PortType::Field3D, "any field on the target grid");
    d.output("out", PortType::Field3D, "the painted channel, clamped to 0..1");
    d.tiling(TileRule::pointwise().with_window());
    d.param_string("name", "detail_type").describe("channel name");
    d.param_float("bottom", 0.5).range(0, 1).describe("value at z_min");
    d.param_float("top", 0.5).range(0, 1).describe("value at z_max");
    d.param_float("z_min", 0).with_unit("m").describe("gradient start height");
    d.param_float("z_max", 512).with_unit("m").describe("gradient end height");
    d.param_enum("shape", {"none", "sphere", "box", "capsule"}, "none").describe("region painted with shape_value");
    d.param_float3("a", {{2048, 2048, 256}}).with_unit("m").describe("shape centre / capsule first end");
    d.param_float3("b", {{2048, 2048, 256}}).with_unit("m").describe("capsule second end");
    d.param_float3("half_size", {{256, 256, 128}}).range(0, 1e9).with_unit("m").describe("box half extents");
    d.param_float("radius", 256).range(0, 1e9).with_unit("m").describe("sphere/capsule radius");
    d.param_float("shape_value", 1).range(0, 1).describe("value inside the shape");
    d.param_float("edge", 64).range(0, 1e9).with_unit("m").describe("soft edge of the shape (inside, over this distance)");
    d.param_float("noise_amount", 0).range(0, 1).describe("noise added, centred on 0");
    d.param_float("noise_frequency", 1.0 / 256.0).range(1e-9, 1e6).with_unit("1/m").describe("noise cells per metre");
    d.param_int("seed", 3).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    auto like = ctx.input_field3d("like");
    auto out = ctx.make_field3d(like->resolution(), 1, like->bounds(), {ctx.get_string("name")});
    const GridFrame frame = ctx.frame(*like); // a tiled cook's crop: the whole grid's positions
    const double z0 = ctx.get_float("z_min"), z1 = ctx.get_float("z_max");
    const double bottom = ctx.get_float("bottom"), top = ctx.get_float("top");
    const bool use_shape = ctx.get_string("shape") != "none";
    volume::Shape s;
    if (use_shape) {
        s.kind = volume::parse_shape_kind(ctx.get_string("shape"));
        s.a = ctx.get_float3("a");
        s.b = ctx.get_float3("b");
        s.half_size = ctx.get_float3("half_size");
        s.radius = s.kind == volume::ShapeKind::Box ? 0 : ctx.get_float("radius");
        volume::validate_shape(s);
    }
    const double sv = ctx.get_float("shape_value"), edge = ctx.get_float("edge");
    const double na = ctx.get_float("noise_amount"), nf = ctx.get_float("noise_frequency");
    const uint32_t seed = uint32_t(ctx.get_int("seed"));
    for (int z = 0; z < out->nz(); ++z)
        for (int y = 0; y < out->ny(); ++y)
            for (int x = 0; x < out->nx(); ++x) {
                const Vec3d p = frame.voxel_center(x, y, z);
                const double t = z1 > z0 ? std::clamp((p[2] - z0) / (z1 - z0), 0.0, 1.0) : (p[2] >= z0 ? 1.0 : 0.0);
                double v = bottom + (top - bottom) * t;
                if (use_shape) {
                    const double dd = volume::shape_distance(s, p);
                    const double k = edge > 0 ? std::clamp(-dd / edge, 0.0, 1.0) : (dd < 0 ? 1.0 : 0.0);
                    v += (sv - v) * k;
                }
                if (na > 0) v += na * (noise::value_noise(p[0] * nf, p[1] * nf, p[2] * nf, {{1 << 20, 1 << 20, 1 << 20}}, seed) - 0.5);
                out->at(0, x, y, z) = float(std::clamp(v, 0.0, 1.0));
            }
    ctx.set_output("out", Field3DPtr(out));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/paint", .version = 1, .declare = declare, .cook = cook});
}
