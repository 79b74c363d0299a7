// math/binary: a (op) b for add, sub, mul, div, min, max, pow.
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

const std::vector<std::string> kOps = {"add", "sub", "mul", "div", "min", "max", "pow"};

void declare(NodeDeclaration& d) {
    d.doc("Per-voxel arithmetic a (op) b on 2D or 3D fields; b is a field of the same resolution (1 or N channels) or the constant `b`.");
    d.input("a", PortType::Field, "left operand");
    d.input("b", PortType::Field, "right operand; when unconnected the parameter `b` is used").optional = true;
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "result, same dimensionality and channels as a");
    d.param_enum("op", kOps, "add").describe("operation: add, sub, mul, div, min, max, pow");
    d.param_float("b", 0.0).describe("constant right operand when input b is unconnected");
}

void cook(CookContext& ctx) {
    const std::string& op = ctx.get_string("op");
    const BinaryOp ops[] = {BinaryOp::Add, BinaryOp::Sub, BinaryOp::Mul, BinaryOp::Div, BinaryOp::Min, BinaryOp::Max, BinaryOp::Pow};
    const auto idx = size_t(std::find(kOps.begin(), kOps.end(), op) - kOps.begin());
    Value b = ctx.has_input("b") ? ctx.input("b") : Value{};
    if (op == "div" && b.index() == 0 && ctx.get_float("b") == 0.0) ctx.fail("parameter 'b': division by the constant 0");
    ctx.set_output("out", field_binary(ctx.input("a"), b, ctx.get_float("b"), ops[idx], &ctx.budget()));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "math/binary", .version = 1, .declare = declare, .cook = cook});
}
