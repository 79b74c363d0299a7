// volume/read_points: a point cloud or particle file (PLY, XYZ).
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/graph/node.h"
#include "atlas/io/geometry_files.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Reads points from PLY (float properties such as 'radius' become attributes) or XYZ text ('x y z [radius [weight]]').");
    d.output("out", PortType::Points, "the points, metres");
    d.param_path("file").describe("point file, relative to the graph file");
}

void cook(CookContext& ctx) {
    auto pts = std::make_shared<Points>(io::read_points(ctx.get_path("file")));
    ctx.metric("points", double(pts->positions.size()));
    ctx.set_output("out", PointsPtr(pts));
}

void hash_extra(const NodeParams& p, Hasher& h) { hash_file(h, p.get_path("file")); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/read_points", .version = 1, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
