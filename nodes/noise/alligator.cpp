// noise/alligator: Alligator (cellular billow) noise.
#include "noise_node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Alligator noise (Atlas clean-room design, docs/noise.md): largest minus second-largest of random-height smooth bumps around one feature point per cell. Values in [0, 1).");
    noise_nodes::declare_common(d);
    d.param_float("radius", 1).range(0.25, 1).with_unit("cells").describe("bump radius");
}

void cook(CookContext& ctx) {
    noise::NoiseSpec s;
    s.kernel = noise::Kernel::Alligator;
    s.alligator.radius = ctx.get_float("radius");
    noise_nodes::cook_noise(ctx, s);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/alligator", .version = 1, .declare = declare, .cook = cook});
}
