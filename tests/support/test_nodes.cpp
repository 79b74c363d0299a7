#include "test_nodes.h"

#include <thread>

namespace atlas::test {

namespace {
Field3DPtr constant_field(const CookContext& ctx, float v) {
    auto f = ctx.make_field3d({{8, 8, 4}}, 1, Box3d{{{0, 0, 0}}, {{8, 8, 4}}});
    std::fill(f->channel(0).begin(), f->channel(0).end(), v);
    return f;
}
} // namespace

NodeRegistry test_registry(std::shared_ptr<CookLog> log) {
    NodeRegistry r = builtin_nodes();
    r.add({.name = "test/source", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("Constant 8x8x4 field.");
               d.output("out", PortType::Field3D, "field");
               d.param_float("value", 1.0).range(-100, 100).describe("value");
               d.param_int("delay_ms", 0).range(0, 1000).describe("sleep before finishing");
           },
           .cook = [log](CookContext& ctx) {
               log->record(ctx.node_name());
               if (ctx.get_int("delay_ms") > 0) std::this_thread::sleep_for(std::chrono::milliseconds(ctx.get_int("delay_ms")));
               ctx.set_output("out", constant_field(ctx, float(ctx.get_float("value"))));
           }});
    r.add({.name = "test/add", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("a + b.");
               d.input("a", PortType::Field3D, "a");
               d.input("b", PortType::Field3D, "b");
               d.output("out", PortType::Field3D, "sum");
           },
           .cook = [log](CookContext& ctx) {
               log->record(ctx.node_name());
               auto a = ctx.input_field3d("a"), b = ctx.input_field3d("b");
               auto f = ctx.make_field3d(a->resolution(), 1, a->bounds());
               for (size_t i = 0; i < f->voxel_count(); ++i) f->channel(0)[i] = a->channel(0)[i] + b->channel(0)[i];
               ctx.set_output("out", Field3DPtr(f));
           }});
    r.add({.name = "test/mesh", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("A one-triangle mesh.");
               d.output("mesh", PortType::Mesh, "mesh");
           },
           .cook = [log](CookContext& ctx) {
               log->record(ctx.node_name());
               auto m = std::make_shared<Mesh>();
               m->vertices = {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}};
               m->triangles = {{0, 1, 2}};
               ctx.set_output("mesh", MeshPtr(m));
           }});
    // Reads log->leaky_value without declaring it: a node whose hash is incomplete.
    r.add({.name = "test/leaky", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("Reads hidden state (bug on purpose).");
               d.output("out", PortType::Field3D, "field");
           },
           .cook = [log](CookContext& ctx) {
               log->record(ctx.node_name());
               ctx.set_output("out", constant_field(ctx, float(log->leaky_value.load())));
           }});
    r.add({.name = "test/fail", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("Throws when the log says so.");
               d.input("in", PortType::Field3D, "passed through");
               d.output("out", PortType::Field3D, "field");
               d.param_int("salt", 0).describe("changes the hash");
           },
           .cook = [log](CookContext& ctx) {
               log->record(ctx.node_name());
               if (log->fail.load()) ctx.fail("simulated failure");
               ctx.set_output("out", ctx.input("in"));
           }});
    r.add({.name = "test/big", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("Asks for a huge field.");
               d.output("out", PortType::Field3D, "field");
           },
           .cook = [](CookContext& ctx) {
               ctx.set_output("out", Field3DPtr(ctx.make_field3d({{4096, 4096, 4096}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}})));
           }});
    return r;
}

} // namespace atlas::test
