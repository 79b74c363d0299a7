// noise/gradient: tileable Perlin gradient noise.
#include "noise_node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Tileable Perlin (gradient) noise with fractal octaves; values in [-1, 1] (fbm). Tiles exactly every `period` lattice cells.");
    noise_nodes::declare_common(d);
}

void cook(CookContext& ctx) {
    noise::NoiseSpec s;
    s.kernel = noise::Kernel::Gradient;
    noise_nodes::cook_noise(ctx, s);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/gradient", .version = 1, .declare = declare, .cook = cook});
}
