// sim/sequence_frame: one frame of the solver's sequence, for a graph that cooks frames.
#include "atlas/graph/node.h"
#include "atlas/sim/sequence.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("One grid of sim/cloud_growth's 'sequence' at a frame: frame 1 is the first kept step. A fractional frame crossfades "
          "the two frames around it voxel by voxel, so keying `frame` over the graph's time (docs/graph-format.md, \"Time\") "
          "plays the growth at any frame rate, and `atlas cook --frames` writes one NVDF set (SDF, BC textures) per frame "
          "from what follows this node.");
    d.input("sequence", PortType::Field3D, "sim/cloud_growth's 'sequence' (channels 'NNNN:GRID')");
    d.output("out", PortType::Field3D, "the grid at the frame (1 channel; vel: vel.x, vel.y, vel.z), on the solver's grid");
    d.tiling(TileRule::pointwise());
    d.param_float("frame", 1).range(1, 1e6).describe("frame number, 1 .. the sequence's last; fractional frames crossfade");
    d.param_enum("grid", {"density", "temperature", "vapor", "vel"}, "density").describe("which of the frame's grids");
}

void cook(CookContext& ctx) {
    const Field3DPtr seq = ctx.input_field3d("sequence");
    try {
        ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(
                                   sim::sequence_frame(*seq, ctx.get_string("grid"), ctx.get_float("frame"), &ctx.budget()))));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "sim/sequence_frame", .version = 1, .declare = declare, .cook = cook});
}
