// import/vdb: float grids from an OpenVDB file (e.g. a fluid cache) as a dense 3D field.
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/graph/node.h"
#include "atlas/io/vdb.h"

#include <sstream>

namespace {
using namespace atlas;

std::vector<std::string> split_names(const std::string& s) {
    std::vector<std::string> v;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) v.push_back(item);
    return v;
}

void declare(NodeDeclaration& d) {
    d.doc("Reads float (and Vec3f) grids from a VDB file, densified over their active bounds, one channel per grid.");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field3D, "dense field, one channel per grid (3 for a vector grid)");
    d.param_path("file").describe("VDB file, relative to the graph file");
    d.param_string("grids", "").describe("comma-separated grid names to read (empty: every float grid)");
}

void cook(CookContext& ctx) {
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(io::read_vdb(ctx.get_path("file"), split_names(ctx.get_string("grids"))))));
}

void hash_extra(const NodeParams& p, Hasher& h) { hash_file(h, p.get_path("file")); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "import/vdb", .version = 1, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
