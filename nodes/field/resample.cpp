// field/resample: a 3D field onto a new resolution and bounds, trilinearly.
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Trilinear (bilinear for 2D) resampling onto a new resolution; bounds default to the input's.");
    d.input("in", PortType::Field, "field to resample");
    d.tiling(TileRule::none("it changes the grid (tiles are regions of one grid)"));
    d.output("out", PortType::Field, "resampled field, same dimensionality");
    d.param_int3("resolution", {{64, 64, 16}}).range(1, 65536).with_unit("voxels").describe("new resolution (z ignored for 2D)");
    d.param_bool("keep_bounds", true).describe("keep the input's world bounds (else use bounds_min/bounds_max)");
    d.param_float3("bounds_min", {{0, 0, 0}}).with_unit("m").describe("new minimum corner when keep_bounds is false");
    d.param_float3("bounds_max", {{1, 1, 1}}).with_unit("m").describe("new maximum corner when keep_bounds is false");
    d.param_enum("wrap", {"clamp", "wrap"}, "clamp").describe("outside the source: repeat the edge (clamp) or tile (wrap)");
}

void cook(CookContext& ctx) {
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
