// Parameters and node declarations as Python data. Used by the module (Session.set,
// nodes(), node_types()) and by Python node types (their declaration and ctx.params),
// so it lives apart from both.
#pragma once

#include "bindings.h"

#include <string>

namespace atlas::python {

// Python values <-> ParamValue; `what` ("node.param") names the value in the TypeError.
py::object param_to_python(const ParamValue& v, ParamType type);
ParamValue param_from_python(const py::handle& o, ParamType type, const std::string& what);
// A declaration as plain data (dicts and lists), the shape add_python_node takes.
py::dict declaration_to_python(const NodeType& type);

} // namespace atlas::python
