// A node declaration from plain data (atlas/graph/node_builder.h).
#include "atlas/graph/node_builder.h"

#include <utility>

namespace atlas {

PortType port_type_named(std::string_view name) {
    for (PortType t : {PortType::Field2D, PortType::Field3D, PortType::Field, PortType::Mesh, PortType::Points})
        if (port_type_name(t) == name) return t;
    throw DeclarationError("unknown port type '" + std::string(name) + "' (expected field2d, field3d, field, mesh or points)");
}

ParamType param_type_named(std::string_view name) {
    using T = ParamType;
    for (T t : {T::Float, T::Int, T::Bool, T::String, T::Enum, T::Path, T::Float2, T::Float3, T::Int2, T::Int3})
        if (param_type_name(t) == name) return t;
    throw DeclarationError("unknown parameter type '" + std::string(name) +
                           "' (expected float, int, bool, string, enum, path, float2, float3, int2 or int3)");
}

NodeDeclarationBuilder::NodeDeclarationBuilder(std::string node, std::string doc) : node_(std::move(node)), doc_(std::move(doc)) {}

void NodeDeclarationBuilder::input(PortDecl port) { inputs_.push_back(std::move(port)); }

void NodeDeclarationBuilder::output(PortDecl port) {
    port.optional = false; // every output is set by the cook
    outputs_.push_back(std::move(port));
}

void NodeDeclarationBuilder::check_ports() const {
    if (outputs_.empty()) throw DeclarationError(node_ + ": a node needs at least one output");
}

void NodeDeclarationBuilder::param(ParamDecl p) {
    check_ports();
    const int n = param_components(p.type);
    const auto* v = std::get_if<std::vector<double>>(&p.default_value);
    if (n > 1 && v && int(v->size()) != n)
        throw DeclarationError(node_ + "." + p.name + ": default needs " + std::to_string(n) + " values");
    // Before declare() turns an integer vector into ints: past their range that is undefined.
    if (std::string err = p.check(p.default_value); !err.empty()) throw DeclarationError(node_ + "." + p.name + ": default: " + err);
    params_.push_back(std::move(p));
}

void NodeDeclarationBuilder::declare(NodeDeclaration& d) const {
    check_ports();
    using T = ParamType;
    d.doc(doc_);
    for (const PortDecl& in : inputs_) d.input(in.name, in.type, in.doc).optional = in.optional;
    for (const PortDecl& out : outputs_) d.output(out.name, out.type, out.doc);
    for (const ParamDecl& p : params_) {
        ParamDecl* q = nullptr;
        const auto* v = std::get_if<std::vector<double>>(&p.default_value);
        switch (p.type) {
        case T::Float: q = &d.param_float(p.name, std::get<double>(p.default_value)); break;
        case T::Int: q = &d.param_int(p.name, std::get<int64_t>(p.default_value)); break;
        case T::Bool: q = &d.param_bool(p.name, std::get<bool>(p.default_value)); break;
        case T::String: q = &d.param_string(p.name, std::get<std::string>(p.default_value)); break;
        case T::Enum: q = &d.param_enum(p.name, p.choices, std::get<std::string>(p.default_value)); break;
        case T::Path: q = &d.param_path(p.name, std::get<std::string>(p.default_value)); break;
        case T::Float2: q = &d.param_float2(p.name, Vec2d{{(*v)[0], (*v)[1]}}); break;
        case T::Float3: q = &d.param_float3(p.name, Vec3d{{(*v)[0], (*v)[1], (*v)[2]}}); break;
        case T::Int2: q = &d.param_int2(p.name, Vec2i{{int((*v)[0]), int((*v)[1])}}); break;
        case T::Int3: q = &d.param_int3(p.name, Vec3i{{int((*v)[0]), int((*v)[1]), int((*v)[2])}}); break;
        }
        q->min = p.min;
        q->max = p.max;
        q->unit = p.unit;
        q->doc = p.doc;
    }
}

} // namespace atlas
