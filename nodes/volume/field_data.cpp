// volume/field_data: encode an SDF (metres) as Nubis field data, or decode it back.
#include "atlas/volume/nvdf.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("encode: SDF metres -> saturate((d - range_min) / (range_max - range_min)) (Nubis: -256..4096 m, so a TGA byte R "
          "decodes as R/255*4352 - 256 m); decode: the inverse, 0..1 -> metres.");
    d.input("in", PortType::Field3D, "SDF in metres (encode) or encoded field data (decode)");
    d.output("out", PortType::Field3D, "channel 'field_data' (encode) or 'sdf' (decode)");
    d.tiling(TileRule::pointwise());
    d.param_enum("mode", {"encode", "decode"}, "encode").describe("direction");
    d.param_float("range_min", -256).with_unit("m").describe("distance mapped to 0");
    d.param_float("range_max", 4096).with_unit("m").describe("distance mapped to 1");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field3d("in");
    const double lo = ctx.get_float("range_min"), hi = ctx.get_float("range_max");
    Field3D out = ctx.get_string("mode") == "encode" ? volume::encode_field_data(*in, lo, hi, 0, &ctx.budget())
                                                     : volume::decode_field_data(*in, lo, hi, 0, &ctx.budget());
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(std::move(out))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/field_data", .version = 1, .declare = declare, .cook = cook});
}
