// import/tga_slices: a 3D field from a TGA slice stack (the Nubis voxel-cloud-pack layout).
#include "atlas/core/files.h"
#include "common/grid.h"
#include "atlas/core/hash.h"
#include "atlas/graph/node.h"
#include "atlas/io/tga_slices.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Reads a stack of TGA slices (NAME.001.tga, NAME.002.tga, ... or the Nubis pack's NAME(0).tga, NAME(1).tga, ...; one per z; "
          "uncompressed or RLE, 8-bit grey, 24 or 32 bits) as a 3D field with 8-bit values mapped to 0..1 (channels r, g, b, a).");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field3D, "the stack as a 3D field (x = column, y = row from the bottom, z = slice)");
    d.param_path("file").describe("the first slice (NAME.001.tga or NAME(0).tga), a pattern or DIR/NAME, relative to the graph file");
    grid_nodes::declare_bounds(d, grid_nodes::kCloudscapeGrid.bounds_min, grid_nodes::kCloudscapeGrid.bounds_max);
    d.param_int("channels", 4).range(1, 4).describe("channels to keep (R, RG, RGB or RGBA)");
}

void cook(CookContext& ctx) {
    Box3d b{ctx.get_float3("bounds_min"), ctx.get_float3("bounds_max")};
    if (!b.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(io::read_tga_slices(ctx.get_path("file"), b, int(ctx.get_int("channels"))))));
}

// Every slice of the stack is an input: hash them all.
void hash_extra(const NodeParams& p, Hasher& h) {
    for (const auto& f : io::find_tga_slices(p.get_path("file"))) hash_file(h, f);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "import/tga_slices", .version = 2, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
