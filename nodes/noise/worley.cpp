// noise/worley: tileable Worley (cellular) noise.
#include "noise_node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Tileable Worley noise: F1, F2, F2-F1 or 1-F1 distances (in cells, clamped to [0, 1]) under a Euclidean, Manhattan or Chebyshev metric.");
    noise_nodes::declare_common(d);
    d.param_enum("feature", {"f1", "f2", "f2-f1", "inverted-f1"}, "inverted-f1").describe("which distance");
    d.param_enum("metric", {"euclidean", "manhattan", "chebyshev"}, "euclidean").describe("distance metric");
    d.param_float("jitter", 1).range(0, 1).describe("feature point spread inside its cell (0 = cell centres)");
}

void cook(CookContext& ctx) {
    noise::NoiseSpec s;
    s.kernel = noise::Kernel::Worley;
    s.worley.feature = noise::parse_worley_feature(ctx.get_string("feature"));
    s.worley.metric = noise::parse_worley_metric(ctx.get_string("metric"));
    s.worley.jitter = ctx.get_float("jitter");
    noise_nodes::cook_noise(ctx, s);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/worley", .version = 1, .declare = declare, .cook = cook});
}
