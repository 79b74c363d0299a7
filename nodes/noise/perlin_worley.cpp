// noise/perlin_worley: Perlin-Worley noise (GPU Pro 7).
#include "noise_node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Perlin-Worley noise (Schneider, GPU Pro 7): the Perlin fractal mapped to [0, 1], remapped with an inverted-Worley FBM as the new minimum: W + P (1 - W). Values in [0, 1].");
    noise_nodes::declare_common(d);
    d.param_int("worley_octaves", 3).range(1, 8).describe("octaves of the inverted-Worley FBM (lacunarity 2, gain 0.5)");
    d.param_int("worley_frequency_ratio", 1).range(1, 64).describe("Worley base period = period x this");
}

void cook(CookContext& ctx) {
    noise::NoiseSpec s;
    s.kernel = noise::Kernel::PerlinWorley;
    s.perlin_worley.worley_octaves = int(ctx.get_int("worley_octaves"));
    s.perlin_worley.worley_frequency_ratio = int(ctx.get_int("worley_frequency_ratio"));
    noise_nodes::cook_noise(ctx, s);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/perlin_worley", .version = 1, .declare = declare, .cook = cook});
}
