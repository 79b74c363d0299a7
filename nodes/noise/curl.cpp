// noise/curl: divergence-free curl noise.
#include "noise_node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Curl noise: 3 channels (3D: curl of three decorrelated gradient noises) or 2 (2D: rotated gradient), per lattice cell; |component| <= 21 (3D) / 10.5 (2D), RMS about 1. Use remap to store in [0, 1]. Only the fbm combinator.");
    noise_nodes::declare_common(d);
}

void cook(CookContext& ctx) {
    noise::NoiseSpec s;
    s.kernel = noise::Kernel::Curl;
    noise_nodes::cook_noise(ctx, s);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/curl", .version = 1, .declare = declare, .cook = cook});
}
