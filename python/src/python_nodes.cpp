// Node types written in Python: the declaration is plain data (the shape
// atlas.node_types() returns), the cook is a Python function taking a
// CookContext (NumPy in, NumPy out). They are hashed (type, version,
// parameters, inputs, and the cook function's code) and cached like any other.
#include "bindings.h"
#include "errors.h"
#include "params.h"

#include "atlas/core/hash.h"
#include "atlas/graph/node_builder.h"

namespace atlas::python {

namespace {

template <typename T>
T get_or(const py::dict& d, const char* key, T def) {
    return d.contains(key) && !d[key].is_none() ? d[key].cast<T>() : def;
}

// The declaration, read from Python data once (with the GIL) at registration: the
// Python values become the library builder's plain data (atlas/graph/node_builder.h),
// which checks them as it checks the C API's JSON. Its refusals are ValueErrors.
NodeDeclarationBuilder parse_declaration(const std::string& node, const std::string& doc, const py::list& inputs,
                                         const py::list& outputs, const py::list& params) {
    NodeDeclarationBuilder d(node, doc);
    auto ports = [&](const py::list& list, bool is_input) {
        for (auto item : list) {
            auto p = item.cast<py::dict>();
            if (!p.contains("name")) throw py::value_error(node + ": a port needs a 'name'");
            PortDecl port{p["name"].cast<std::string>(), port_type_named(get_or<std::string>(p, "type", "field")),
                          get_or<std::string>(p, "doc", ""), get_or<bool>(p, "optional", false)};
            if (is_input) d.input(std::move(port));
            else d.output(std::move(port));
        }
    };
    ports(inputs, true);
    ports(outputs, false);
    d.check_ports();
    for (auto item : params) {
        auto p = item.cast<py::dict>();
        if (!p.contains("name") || !p.contains("type") || !p.contains("default"))
            throw py::value_error(node + ": a parameter needs 'name', 'type' and 'default'");
        ParamDecl pd;
        pd.name = p["name"].cast<std::string>();
        pd.type = param_type_named(p["type"].cast<std::string>());
        pd.default_value = param_from_python(p["default"], pd.type, node + "." + pd.name + " default");
        if (p.contains("min") && !p["min"].is_none()) pd.min = p["min"].cast<double>();
        if (p.contains("max") && !p["max"].is_none()) pd.max = p["max"].cast<double>();
        pd.unit = get_or<std::string>(p, "unit", "");
        pd.doc = get_or<std::string>(p, "doc", "");
        pd.choices = get_or<std::vector<std::string>>(p, "choices", {});
        d.param(std::move(pd));
    }
    return d;
}

// What a Python cook function sees. Valid only during the cook call.
class PyCookContext {
public:
    explicit PyCookContext(CookContext* ctx, const NodeDeclaration* decl) : ctx_(ctx), decl_(decl) {}
    void invalidate() { ctx_ = nullptr; }

    CookContext& ctx() const {
        if (!ctx_) throw Error("a CookContext is only valid during its node's cook");
        return *ctx_;
    }
    std::string node_name() const { return ctx().node_name(); }
    py::dict params() const {
        const CookContext& c = ctx();
        py::dict d;
        for (const ParamDecl& p : decl_->params()) d[py::str(p.name)] = param_to_python(c.params().get(p.name), p.type);
        return d;
    }
    py::object param(const std::string& name) const {
        const ParamDecl* p = decl_->find_param(name);
        if (!p) throw Error("node '" + node_name() + "': no parameter '" + name + "'");
        return param_to_python(ctx().params().get(name), p->type);
    }
    std::string path(const std::string& name) const { return ctx().get_path(name).string(); }
    bool has_input(const std::string& port) const { return ctx().has_input(port); }
    py::object input(const std::string& port) const {
        if (!decl_->find_input(port)) throw Error("node '" + node_name() + "': no input port '" + port + "'");
        if (!ctx().has_input(port)) return py::none();
        return value_to_python(ctx().input(port));
    }
    py::dict inputs() const {
        ctx();
        py::dict d;
        for (const PortDecl& p : decl_->inputs())
            d[py::str(p.name)] = ctx().has_input(p.name) ? value_to_python(ctx().input(p.name)) : py::none();
        return d;
    }
    void set_output(const std::string& port, const py::object& value, const py::object& bounds, const py::object& channel_names) {
        CookContext& c = ctx();
        const PortDecl* out = decl_->find_output(port);
        if (!out) throw Error("node '" + node_name() + "': no output port '" + port + "'");
        Value v = python_to_value(value);
        if (std::holds_alternative<std::monostate>(v)) {
            if (!py::isinstance<py::array>(value))
                throw Error("node '" + node_name() + "': output '" + port + "' takes an atlas field or a NumPy array");
            int dims = out->type == PortType::Field2D ? 2 : out->type == PortType::Field3D ? 3 : 0;
            if (out->type == PortType::Mesh || out->type == PortType::Points)
                throw Error("node '" + node_name() + "': output '" + port + "' is a " + std::string(port_type_name(out->type)) +
                            "; Python nodes produce fields");
            const py::array array(value);
            const int d = dims == 0 ? array.ndim() == 2 ? 2 : 3 : dims;
            const int channels = array.ndim() == d + 1 ? int(array.shape(0)) : 1;
            py::object b = bounds;
            if (b.is_none()) b = first_input_bounds(d);
            // Still none: field_from_array checks the shape first, then asks for bounds.
            py::object names = channel_names;
            if (names.is_none()) names = first_input_channel_names(d, channels);
            v = field_from_array(array, dims, b, names, &c.budget());
        }
        if (!port_accepts(out->type, value_type(v)))
            throw Error("node '" + node_name() + "': output '" + port + "' is a " + std::string(port_type_name(out->type)) +
                        ", got a " + std::string(port_type_name(value_type(v))));
        c.set_output(port, std::move(v));
    }
    void progress(double f) const {
        py::gil_scoped_release nogil; // the host's progress callback takes the GIL itself
        ctx().progress(f);
    }
    void warn(const std::string& m) { ctx().warn(m); }
    void metric(const std::string& name, double v) { ctx().metric(name, v); }

private:
    // Outputs default to the world box of the first field input of the same dimensionality.
    py::object first_input_bounds(int dims) const {
        for (const PortDecl& p : decl_->inputs()) {
            if (!ctx().has_input(p.name)) continue;
            const Value& v = ctx().input(p.name);
            if (auto* f = std::get_if<Field3DPtr>(&v); f && dims == 3)
                return py::make_tuple(py::make_tuple((*f)->bounds().min[0], (*f)->bounds().min[1], (*f)->bounds().min[2]),
                                      py::make_tuple((*f)->bounds().max[0], (*f)->bounds().max[1], (*f)->bounds().max[2]));
            if (auto* f = std::get_if<Field2DPtr>(&v); f && dims == 2)
                return py::make_tuple(py::make_tuple((*f)->bounds().min[0], (*f)->bounds().min[1]),
                                      py::make_tuple((*f)->bounds().max[0], (*f)->bounds().max[1]));
        }
        return py::none();
    }
    // Channel names default to those of the first field input of the same
    // dimensionality and channel count (docs/embedding.md), else r, g, b, a.
    py::object first_input_channel_names(int dims, int channels) const {
        for (const PortDecl& p : decl_->inputs()) {
            if (!ctx().has_input(p.name)) continue;
            const Value& v = ctx().input(p.name);
            const std::vector<std::string>* names = nullptr;
            if (auto* f = std::get_if<Field3DPtr>(&v); f && dims == 3) names = &(*f)->channel_names();
            if (auto* f = std::get_if<Field2DPtr>(&v); f && dims == 2) names = &(*f)->channel_names();
            if (names && int(names->size()) == channels) return py::cast(*names);
        }
        return py::none();
    }
    CookContext* ctx_;
    const NodeDeclaration* decl_;
};

// What identifies a Python function's behaviour for the hash: its bytecode,
// constants and names (best effort; helpers it calls are not included - bump
// the version when they change).
std::string code_identity(const py::object& fn) {
    if (!py::hasattr(fn, "__code__")) return "";
    py::object code = fn.attr("__code__");
    std::string id = py::bytes(code.attr("co_code")).cast<std::string>();
    id += py::repr(code.attr("co_consts")).cast<std::string>();
    id += py::repr(code.attr("co_names")).cast<std::string>();
    return id;
}

void add_python_node(NodeRegistry& registry, const std::string& name, const py::object& cook, int version,
                     const std::string& doc, const py::list& inputs, const py::list& outputs, const py::list& params) {
    if (!PyCallable_Check(cook.ptr())) throw py::type_error(name + ": cook must be callable");
    std::shared_ptr<const NodeDeclarationBuilder> decl;
    try {
        decl = std::make_shared<const NodeDeclarationBuilder>(parse_declaration(name, doc, inputs, outputs, params));
    } catch (const DeclarationError& e) {
        throw py::value_error(e.what());
    }
    const std::string code = code_identity(cook);
    SharedPyObject fn(cook);
    // The same declaration the registry builds, for the cook context's lookups.
    auto built = std::make_shared<NodeDeclaration>();
    decl->declare(*built);
    NodeType t;
    t.name = name;
    t.version = version;
    t.declare = [decl](NodeDeclaration& d) { decl->declare(d); };
    t.cook = [fn, built](CookContext& ctx) {
        // Runs on a worker thread with the GIL released by Session.cook.
        py::gil_scoped_acquire gil;
        py::object pyctx = py::cast(PyCookContext(&ctx, built.get()));
        auto& c = pyctx.cast<PyCookContext&>();
        try {
            fn.get()(pyctx);
        } catch (py::error_already_set& e) {
            c.invalidate();
            if (e.matches(PyExc_KeyboardInterrupt)) throw CancelledError();
            throw Error(python_error_message(e));
        }
        c.invalidate();
    };
    t.hash_extra = [code](const NodeParams&, Hasher& h) { h.add("python-cook").add(code); };
    registry.add(std::move(t));
}

} // namespace

void bind_python_nodes(py::module_& m) {
    py::class_<PyCookContext>(m, "CookContext", R"doc(
What a Python node's cook(ctx) sees: its parameters and inputs, and where its
outputs go. Valid only during that call.)doc")
        .def_property_readonly("node_name", &PyCookContext::node_name)
        .def_property_readonly("params", &PyCookContext::params, "Resolved parameters {name: value}.")
        .def("param", &PyCookContext::param, py::arg("name"))
        .def("path", &PyCookContext::path, py::arg("name"), "A path parameter resolved against the graph file's directory.")
        .def("has_input", &PyCookContext::has_input, py::arg("port"))
        .def("input", &PyCookContext::input, py::arg("port"), "The value on an input port (a Field2D/Field3D), None when unconnected.")
        .def_property_readonly("inputs", &PyCookContext::inputs)
        .def("set_output", &PyCookContext::set_output, py::arg("port"), py::arg("value"), py::arg("bounds") = py::none(),
             py::arg("channel_names") = py::none(),
             "Sets an output from an atlas field or a NumPy array (copied into a new field; bounds default to the first "
             "field input's). Arrays: (nz, ny, nx) or (channels, nz, ny, nx) for 3D, (ny, nx) or (channels, ny, nx) for 2D.")
        .def("progress", &PyCookContext::progress, py::arg("fraction"), "Reports progress 0..1 within this node; raises atlas.CancelledError when cancelled.")
        .def("warn", &PyCookContext::warn, py::arg("message"))
        .def("metric", &PyCookContext::metric, py::arg("name"), py::arg("value"));

    py::class_<NodeRegistry>(m, "NodeRegistry", "A set of node types (copy it into a Session).")
        .def(py::init<>(), "An empty registry (atlas.builtin_nodes() has Atlas's own).")
        .def("names", &NodeRegistry::names)
        .def("__contains__", [](const NodeRegistry& r, const std::string& n) { return r.find(n) != nullptr; })
        .def("__len__", [](const NodeRegistry& r) { return r.names().size(); })
        .def("declaration", [](const NodeRegistry& r, const std::string& type) {
                 const NodeType* t = r.find(type);
                 if (!t) throw Error("unknown node type '" + type + "'" + name_hint(type, r.names()));
                 return declaration_to_python(*t);
             }, py::arg("type"))
        .def("declarations", [](const NodeRegistry& r) {
                 py::list l;
                 for (const NodeType* t : r.all()) l.append(declaration_to_python(*t));
                 return l;
             })
        .def("add_python_node", &add_python_node, py::arg("name"), py::arg("cook"), py::arg("version") = 1,
             py::arg("doc") = "", py::arg("inputs") = py::list(), py::arg("outputs") = py::list(), py::arg("params") = py::list(),
             R"doc(Registers a node type written in Python.

inputs/outputs: [{"name", "type": "field3d"|"field2d"|"field"|"mesh"|"points", "doc", "optional"}]
params: [{"name", "type": "float"|"int"|"bool"|"string"|"enum"|"path"|"float2"|"float3"|"int2"|"int3",
          "default", "min", "max", "unit", "doc", "choices"}] - the shape node_types() returns.
cook(ctx) reads ctx.params / ctx.input(port) and calls ctx.set_output(port, array_or_field).
Its results are hashed from the type, version, parameters, inputs and the cook function's code,
and cached like any node's; bump `version` when code it calls changes.)doc");

    m.def("builtin_nodes", &builtin_nodes, "A new registry of Atlas's own node types.");
    m.def("node_types", [] {
        py::list l;
        NodeRegistry r = builtin_nodes();
        for (const NodeType* t : r.all()) l.append(declaration_to_python(*t));
        return l;
    }, "Every built-in node type's declaration as plain data: [{name, version, doc, inputs, outputs, params}].");
}

} // namespace atlas::python
