// import/image: read a PNG, TGA, EXR, ... (anything OpenImageIO reads) as a 2D field.
#include "atlas/core/files.h"
#include "common/grid.h"
#include "atlas/core/hash.h"
#include "atlas/graph/node.h"
#include "atlas/io/image.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Reads an image through OpenImageIO as a 2D field over the given world bounds; 8/16-bit values map to 0..1.");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "the image as a 2D field (row 0 is the bottom row)");
    d.param_path("file").describe("image file, relative to the graph file");
    grid_nodes::declare_map_bounds(d, grid_nodes::kCloudscapeMap.bounds_min, grid_nodes::kCloudscapeMap.bounds_max);
}

void cook(CookContext& ctx) {
    Box2d b{ctx.get_float2("bounds_min"), ctx.get_float2("bounds_max")};
    if (!b.valid()) ctx.fail("bounds_max must be greater than bounds_min in x and y");
    ctx.set_output("out", Field2DPtr(std::make_shared<Field2D>(io::read_image(ctx.get_path("file"), b))));
}

void hash_extra(const NodeParams& p, Hasher& h) { hash_file(h, p.get_path("file")); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "import/image", .version = 1, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
