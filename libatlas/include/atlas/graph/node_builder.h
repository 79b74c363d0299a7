// atlas/graph/node_builder.h - a node type's declaration made from plain data, as a
// host declares its own node types at run time (the C API's JSON, the Python
// module's dicts; the shape atlas_session_node_types_json / atlas.node_types()
// return). Both front ends go through this one builder, so they accept the same
// declarations and refuse the others with the same messages; each only turns its
// own values (a JSON number, a Python int) into the plain data taken here.
#pragma once

#include "atlas/core/error.h"
#include "atlas/core/value.h"
#include "atlas/graph/node.h"
#include "atlas/graph/param.h"

#include <string>
#include <string_view>
#include <vector>

namespace atlas {

// A declaration that cannot be used. The front ends report it as their own kind of
// error: the C API as ATLAS_INVALID_ARGUMENT, Python as ValueError.
class DeclarationError : public Error {
public:
    using Error::Error;
};

// The port type named `name` (port_type_name: field2d, field3d, field, mesh, points);
// throws DeclarationError listing them.
PortType port_type_named(std::string_view name);
// The parameter type named `name` (param_type_name: float, int, ... int3), which a
// front end needs to convert a default; throws DeclarationError listing them.
ParamType param_type_named(std::string_view name);

// A declaration checked as its parts are given (ports, then parameters, in the host's
// order), so the first problem is the one reported, and then replayed into the
// registry's NodeDeclaration by declare(). Not thread-safe while being built; a
// finished builder is read-only and may be shared (NodeType::declare keeps one).
class NodeDeclarationBuilder {
public:
    // `node` (the type's name) prefixes the messages.
    explicit NodeDeclarationBuilder(std::string node, std::string doc = "");

    // A port: name, type (port_type_named), doc, and for an input whether it is optional.
    void input(PortDecl port);
    void output(PortDecl port);
    // After the ports: throws DeclarationError "<node>: a node needs at least one output"
    // (param() and declare() check it too; a front end calls it before it reads the
    // parameters, so that is the problem reported first).
    void check_ports() const;

    // One parameter: name, type, default_value (of the type's ParamValue alternative;
    // a vector type's default holds param_components(type) numbers), min, max, unit,
    // doc and, for an enum, choices. Throws DeclarationError "<node>.<name>: default
    // needs N values", or "<node>.<name>: default: <why>" when the default is not a
    // value the parameter takes (ParamDecl::check: type, range, choices, +-2^31 for
    // integer vectors).
    void param(ParamDecl p);

    // Adds the declaration to `d` (typically the registry's). A name declared twice
    // throws atlas::Error from NodeDeclaration, as for a built-in node.
    void declare(NodeDeclaration& d) const;

    const std::string& node() const { return node_; }

private:
    std::string node_, doc_;
    std::vector<PortDecl> inputs_, outputs_;
    std::vector<ParamDecl> params_;
};

} // namespace atlas
