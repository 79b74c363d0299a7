// noise/nubis_set: the Nubis³ voxel cloud noise (shared recipe).
#include "atlas/graph/node.h"
#include "atlas/noise/recipes.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("The Nubis³ voxel cloud noise: size^3 x 4 channels, R/G low/high-frequency Curly-Alligator (wisps), "
          "B/A low/high-frequency Alligator (billows), each normalised to the full 0..1 range; tiles exactly. "
          "The recipe is noise::make_nubis_noise (docs/noise.md).");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field3D, "RGBA noise volume over the unit box");
    d.param_int("size", 128).range(1, 1024).with_unit("voxels").describe("voxels per axis");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("random seed");
}

void cook(CookContext& ctx) {
    const int n = int(ctx.get_int("size"));
    ctx.check_memory(field_bytes(uint64_t(n) * uint64_t(n) * uint64_t(n), 4), "the noise volume");
    auto f = std::make_shared<Field3D>(noise::make_nubis_noise(n, uint32_t(ctx.get_int("seed")), &ctx.progress_sink(), &ctx.budget()));
    ctx.set_output("out", Field3DPtr(f));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/nubis_set", .version = 1, .declare = declare, .cook = cook});
}
