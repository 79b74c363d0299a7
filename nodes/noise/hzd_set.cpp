// noise/hzd_set: the Horizon Zero Dawn noise set (shared recipe).
#include "atlas/graph/node.h"
#include "atlas/noise/recipes.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("The Horizon Zero Dawn noise set (GPU Pro 7): `low` RGBA = Perlin-Worley + 3 inverted-Worley FBMs, "
          "`high` RGB = 3 higher inverted-Worley FBMs, `curl` RG = 2D curl noise remapped to [0, 1]; all tile exactly. "
          "The recipe is noise::make_hzd_noise (docs/noise.md).");
    d.tiling(TileRule::pointwise());
    d.output("low", PortType::Field3D, "low-frequency RGBA volume");
    d.output("high", PortType::Field3D, "high-frequency RGB volume");
    d.output("curl", PortType::Field2D, "2D curl texture (RG)");
    d.param_int("low_size", 128).range(1, 1024).with_unit("voxels").describe("voxels per axis of `low`");
    d.param_int("high_size", 32).range(1, 1024).with_unit("voxels").describe("voxels per axis of `high`");
    d.param_int("curl_size", 128).range(1, 1024).with_unit("texels").describe("texels per axis of `curl`");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("random seed");
}

void cook(CookContext& ctx) {
    const uint64_t lo = uint64_t(ctx.get_int("low_size")), hi = uint64_t(ctx.get_int("high_size")), cu = uint64_t(ctx.get_int("curl_size"));
    ctx.check_memory(field_bytes(lo * lo * lo, 4) + field_bytes(hi * hi * hi, 3) + field_bytes(cu * cu, 2), "the noise set");
    noise::HzdNoise h = noise::make_hzd_noise(int(lo), int(hi), int(cu), uint32_t(ctx.get_int("seed")), &ctx.progress_sink(), &ctx.budget());
    ctx.set_output("low", Field3DPtr(std::make_shared<Field3D>(std::move(h.low))));
    ctx.set_output("high", Field3DPtr(std::make_shared<Field3D>(std::move(h.high))));
    ctx.set_output("curl", Field2DPtr(std::make_shared<Field2D>(std::move(h.curl))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/hzd_set", .version = 1, .declare = declare, .cook = cook});
}
