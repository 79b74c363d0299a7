// field/pack: single-channel fields into one multi-channel field (e.g. RGBA noise).
#include "atlas/graph/node.h"

#include <sstream>

namespace {
using namespace atlas;

const char* kPorts[] = {"r", "g", "b", "a"};

void declare(NodeDeclaration& d) {
    d.doc("Packs up to four fields of one resolution into one field, channel by channel (the first channel of each input), "
          "e.g. four noises into an RGBA noise volume.");
    d.input("r", PortType::Field, "first channel");
    for (int i = 1; i < 4; ++i) d.input(kPorts[i], PortType::Field, std::string("channel ") + kPorts[i] + " (optional)").optional = true;
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "the packed field, same dimensionality as the inputs");
    d.param_string("names", "r,g,b,a").describe("comma-separated channel names of the result, one per connected input");
}

template <typename F>
std::shared_ptr<F> pack(CookContext& ctx, const std::vector<std::shared_ptr<const F>>& in, const std::vector<std::string>& names) {
    const F& first = *in[0];
    for (size_t i = 1; i < in.size(); ++i)
        if (in[i]->resolution() != first.resolution())
            ctx.fail("input '" + std::string(kPorts[i]) + "' has another resolution than input 'r'");
    std::shared_ptr<F> out;
    if constexpr (std::is_same_v<F, Field3D>) out = ctx.make_field3d(first.resolution(), int(in.size()), first.bounds(), names);
    else out = ctx.make_field2d(first.resolution(), int(in.size()), first.bounds(), names);
    for (size_t i = 0; i < in.size(); ++i) std::copy(in[i]->channel(0).begin(), in[i]->channel(0).end(), out->channel(int(i)).begin());
    return out;
}

void cook(CookContext& ctx) {
    std::vector<Value> in;
    for (size_t i = 0; i < 4; ++i) {
        if (!ctx.has_input(kPorts[i])) continue;
        if (in.size() != i) ctx.fail(std::string("input '") + kPorts[i] + "' is connected but an earlier one is not");
        in.push_back(ctx.input(kPorts[i]));
    }
    std::vector<std::string> names;
    std::stringstream ss(ctx.get_string("names"));
    for (std::string n; std::getline(ss, n, ',');) names.push_back(n);
    if (names.size() < in.size()) ctx.fail("parameter 'names' lists " + std::to_string(names.size()) + " names for " + std::to_string(in.size()) + " inputs");
    names.resize(in.size());
    if (std::holds_alternative<Field3DPtr>(in[0])) {
        std::vector<Field3DPtr> f;
        for (size_t i = 0; i < in.size(); ++i) f.push_back(ctx.input_field3d(kPorts[i]));
        ctx.set_output("out", Field3DPtr(pack(ctx, f, names)));
    } else {
        std::vector<Field2DPtr> f;
        for (size_t i = 0; i < in.size(); ++i) f.push_back(ctx.input_field2d(kPorts[i]));
        ctx.set_output("out", Field2DPtr(pack(ctx, f, names)));
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "field/pack", .version = 1, .declare = declare, .cook = cook});
}
