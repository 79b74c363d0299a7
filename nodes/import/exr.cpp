// import/exr: read an EXR written by Atlas (2D or 3D) or any float EXR (2D).
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/graph/node.h"
#include "atlas/io/exr.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Reads an OpenEXR file: Atlas's 3D layout (slices stacked, bounds in the header) or a plain 2D image.");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "the field (3D when the file carries atlas:resolution, else 2D)");
    d.param_path("file").describe("EXR file, relative to the graph file");
}

void cook(CookContext& ctx) { ctx.set_output("out", io::read_exr(ctx.get_path("file"))); }

void hash_extra(const NodeParams& p, Hasher& h) { hash_file(h, p.get_path("file")); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "import/exr", .version = 1, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
