// Parameters and declarations as Python data (params.h).
#include "params.h"

#include <cmath>

namespace atlas::python {

py::object param_to_python(const ParamValue& v, ParamType type) {
    if (auto* b = std::get_if<bool>(&v)) return py::bool_(*b);
    if (auto* i = std::get_if<int64_t>(&v)) return py::int_(*i);
    if (auto* d = std::get_if<double>(&v)) return py::float_(*d);
    if (auto* s = std::get_if<std::string>(&v)) return py::str(*s);
    const auto& vec = std::get<std::vector<double>>(v);
    py::list l;
    const bool ints = type == ParamType::Int2 || type == ParamType::Int3;
    for (double x : vec) {
        if (ints) l.append(py::int_(int64_t(x)));
        else l.append(py::float_(x));
    }
    return l;
}

ParamValue param_from_python(const py::handle& o, ParamType type, const std::string& what) {
    auto bad = [&](const char* expected) {
        return py::type_error(what + ": expected " + expected + ", got " + py::str(py::type::handle_of(o).attr("__name__")).cast<std::string>() +
                              " " + py::repr(o).cast<std::string>());
    };
    switch (type) {
    case ParamType::Bool:
        if (!py::isinstance<py::bool_>(o)) throw bad("a bool");
        return o.cast<bool>();
    case ParamType::Int:
        if (py::isinstance<py::bool_>(o)) throw bad("an int");
        if (py::isinstance<py::int_>(o)) return o.cast<int64_t>();
        if (py::isinstance<py::float_>(o)) {
            double d = o.cast<double>();
            if (std::isfinite(d) && std::floor(d) == d && std::fabs(d) < 9.0e15) return int64_t(d);
        }
        throw bad("an int");
    case ParamType::Float:
        if (py::isinstance<py::bool_>(o) || !(py::isinstance<py::int_>(o) || py::isinstance<py::float_>(o)))
            throw bad("a number");
        return o.cast<double>();
    case ParamType::String:
    case ParamType::Enum:
    case ParamType::Path:
        if (py::hasattr(o, "__fspath__")) return py::str(o.attr("__fspath__")()).cast<std::string>();
        if (!py::isinstance<py::str>(o)) throw bad("a str");
        return o.cast<std::string>();
    default: {
        if (py::isinstance<py::str>(o) || !py::isinstance<py::sequence>(o)) throw bad("a sequence of numbers");
        std::vector<double> v;
        for (auto item : o) {
            if (py::isinstance<py::bool_>(item) || !(py::isinstance<py::int_>(item) || py::isinstance<py::float_>(item)))
                throw bad("a sequence of numbers");
            v.push_back(item.cast<double>());
        }
        return v;
    }
    }
}

py::dict declaration_to_python(const NodeType& t) {
    auto ports = [](const std::deque<PortDecl>& list) {
        py::list l;
        for (const PortDecl& p : list) {
            py::dict d;
            d["name"] = p.name;
            d["type"] = std::string(port_type_name(p.type));
            d["doc"] = p.doc;
            d["optional"] = p.optional;
            l.append(d);
        }
        return l;
    };
    py::list params;
    for (const ParamDecl& p : t.decl.params()) {
        py::dict d;
        d["name"] = p.name;
        d["type"] = std::string(param_type_name(p.type));
        d["default"] = param_to_python(p.default_value, p.type);
        d["min"] = p.min ? py::object(py::float_(*p.min)) : py::object(py::none());
        d["max"] = p.max ? py::object(py::float_(*p.max)) : py::object(py::none());
        d["unit"] = p.unit;
        d["doc"] = p.doc;
        d["choices"] = p.choices;
        params.append(d);
    }
    py::dict d;
    d["name"] = t.name;
    d["version"] = t.version;
    d["doc"] = t.decl.doc();
    d["inputs"] = ports(t.decl.inputs());
    d["outputs"] = ports(t.decl.outputs());
    d["params"] = params;
    return d;
}

} // namespace atlas::python
