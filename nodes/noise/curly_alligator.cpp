// noise/curly_alligator: Curly-Alligator noise (Nubis³).
#include "noise_node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Curly-Alligator noise (Nubis³): inverted Alligator looked up at p + curl_strength * curl(p). Values in [0, 1].");
    noise_nodes::declare_common(d);
    d.param_float("radius", 1).range(0.25, 1).with_unit("cells").describe("Alligator bump radius");
    d.param_float("curl_strength", 0.25).range(0, 16).with_unit("cells").describe("lookup displacement per unit of curl");
    d.param_int("curl_frequency_ratio", 1).range(1, 64).describe("curl period = period x this");
}

void cook(CookContext& ctx) {
    noise::NoiseSpec s;
    s.kernel = noise::Kernel::CurlyAlligator;
    s.alligator.radius = ctx.get_float("radius");
    s.curly.curl_strength = ctx.get_float("curl_strength");
    s.curly.curl_frequency_ratio = int(ctx.get_int("curl_frequency_ratio"));
    noise_nodes::cook_noise(ctx, s);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/curly_alligator", .version = 1, .declare = declare, .cook = cook});
}
