// volume/read_mesh: a triangle mesh file (OBJ, OFF, PLY, STL), repaired for voxelisation.
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/graph/node.h"
#include "volume/mesh_files.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Reads OBJ, OFF, PLY or STL (OBJ and OFF with errors at file:line, PLY and STL through CGAL) and repairs it: duplicate vertices merged, degenerate and duplicate "
          "triangles removed, orientation made consistent and outward.");
    d.output("out", PortType::Mesh, "the repaired mesh, metres");
    d.param_path("file").describe("mesh file, relative to the graph file");
}

void cook(CookContext& ctx) {
    volume::MeshRepairReport rep;
    auto mesh = std::make_shared<Mesh>(volume_nodes::read_mesh_file(ctx.get_path("file"), &rep));
    ctx.metric("triangles", double(mesh->triangles.size()));
    ctx.metric("removed_degenerate", double(rep.removed_degenerate));
    ctx.metric("removed_duplicates", double(rep.removed_duplicates));
    ctx.metric("flipped_triangles", double(rep.flipped_triangles));
    ctx.metric("components", double(rep.components));
    ctx.set_output("out", MeshPtr(mesh));
}

void hash_extra(const NodeParams& p, Hasher& h) { hash_file(h, p.get_path("file")); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/read_mesh", .version = 2, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
