// Graph validation (connections, types, cycles) and parameter overrides.
#include "atlas/graph/graph.h"
#include "graph_walk.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace atlas {

namespace {
// Ports are compatible when some concrete type satisfies both sides.
bool ports_compatible(PortType accepted, PortType produced) {
    return port_accepts(accepted, produced) || (produced == PortType::Field && port_accepts(PortType::Field, accepted));
}

std::vector<std::string> port_names(const std::deque<PortDecl>& ports) {
    std::vector<std::string> v;
    for (const auto& p : ports) v.push_back(p.name);
    return v;
}

std::string with_hint(const std::string& msg, const std::string& word, const std::vector<std::string>& candidates) {
    return msg + name_hint(word, candidates);
}
} // namespace

void validate_graph(const Graph& graph, const NodeRegistry& registry) {
    std::vector<std::string> node_names;
    for (const auto& n : graph.nodes) node_names.push_back(n.name);

    for (const auto& n : graph.nodes) {
        const NodeType* type = registry.find(n.type);
        if (!type) throw ParseError(n.where, "node '" + n.name + "': unknown node type '" + n.type + "'");
        for (const auto& [port, b] : n.inputs) {
            const PortDecl* in = type->decl.find_input(port);
            if (!in)
                throw ParseError(b.where, with_hint("node '" + n.name + "' (" + n.type + "): unknown input '" + port + "'", port,
                                                    port_names(type->decl.inputs())));
            const GraphNode* src = graph.find(b.node);
            if (!src)
                throw ParseError(b.where, with_hint("node '" + n.name + "': input '" + port + "' names unknown node '" + b.node + "'",
                                                    b.node, node_names));
            const NodeType* st = registry.find(src->type);
            std::string sport = b.port;
            if (sport.empty()) {
                if (st->decl.outputs().size() != 1)
                    throw ParseError(b.where, "node '" + n.name + "': input '" + port + "': node '" + b.node +
                                                  "' has several outputs; write '" + b.node + "." + st->decl.outputs().front().name + "'");
                sport = st->decl.outputs().front().name;
            }
            const PortDecl* out = st->decl.find_output(sport);
            if (!out)
                throw ParseError(b.where, with_hint("node '" + n.name + "': input '" + port + "': node '" + b.node + "' (" + src->type +
                                                        ") has no output '" + sport + "'",
                                                    sport, port_names(st->decl.outputs())));
            if (!ports_compatible(in->type, out->type))
                throw ParseError(b.where, "node '" + n.name + "': type mismatch: input '" + port + "' expects a " +
                                              std::string(port_type_name(in->type)) + " but '" + b.node + "." + sport + "' produces a " +
                                              std::string(port_type_name(out->type)));
        }
        for (const auto& in : type->decl.inputs())
            if (!in.optional && !n.inputs.count(in.name))
                throw ParseError(n.where, "node '" + n.name + "' (" + n.type + "): missing input '" + in.name + "' (" +
                                              std::string(port_type_name(in.type)) + ": " + in.doc + ")");
        for (const auto& [pname, setting] : n.params) {
            const ParamDecl* d = type->decl.find_param(pname);
            if (!d) throw ParseError(setting.where, "node '" + n.name + "': unknown parameter '" + pname + "'");
            if (auto err = d->check(setting.value); !err.empty())
                throw ParseError(setting.where, "node '" + n.name + "': parameter '" + pname + "': " + err);
        }
    }

    // Cycles: depth-first search with colours; report the cycle's path.
    std::map<std::string, int> colour; // 0 white, 1 grey, 2 black
    std::vector<std::string> stack;
    std::function<void(const GraphNode&)> visit = [&](const GraphNode& n) {
        colour[n.name] = 1;
        stack.push_back(n.name);
        for (const auto& [port, b] : n.inputs) {
            const GraphNode* src = graph.find(b.node);
            int c = colour[src->name];
            if (c == 1) {
                std::string path;
                auto it = std::find(stack.begin(), stack.end(), src->name);
                for (; it != stack.end(); ++it) path += *it + " -> ";
                path += src->name;
                throw ParseError(b.where, "cycle in the graph: " + path + " (a node cannot depend on its own output)");
            }
            if (c == 0) visit(*src);
        }
        stack.pop_back();
        colour[n.name] = 2;
    };
    for (const auto& n : graph.nodes)
        if (colour[n.name] == 0) visit(n);
}

std::map<std::string, ParamValue> resolved_params(const GraphNode& node, const NodeType& type, int proxy) {
    std::map<std::string, ParamValue> values;
    for (const auto& d : type.decl.params()) values[d.name] = d.default_value;
    for (const auto& [name, setting] : node.params) values[name] = setting.value;
    if (proxy > 1)
        for (const auto& d : type.decl.params()) values[d.name] = d.at_proxy(values[d.name], proxy);
    return values;
}

namespace {
const ParamDecl& find_override_target(Graph& graph, const NodeRegistry& registry, const std::string& node, const std::string& param,
                                      GraphNode*& gn) {
    gn = graph.find(node);
    if (!gn) {
        std::vector<std::string> names;
        for (const auto& n : graph.nodes) names.push_back(n.name);
        throw Error(with_hint("unknown node '" + node + "'", node, names));
    }
    const NodeType* type = registry.find(gn->type);
    const ParamDecl* d = type->decl.find_param(param);
    if (!d) {
        std::vector<std::string> names;
        for (const auto& p : type->decl.params()) names.push_back(p.name);
        throw Error(with_hint("node '" + node + "' (" + gn->type + "): unknown parameter '" + param + "'", param, names));
    }
    return *d;
}
} // namespace

void set_param(Graph& graph, const NodeRegistry& registry, const std::string& node, const std::string& param, const ParamValue& value) {
    GraphNode* gn = nullptr;
    const ParamDecl& d = find_override_target(graph, registry, node, param, gn);
    ParamValue v = value;
    // Hosts may pass an integer where a float is declared.
    if (d.type == ParamType::Float && std::holds_alternative<int64_t>(v)) v = double(std::get<int64_t>(v));
    if (auto err = d.check(v); !err.empty()) throw Error("node '" + node + "': parameter '" + param + "': " + err);
    gn->params[param] = {v, SourceLocation{"<host>", 0, 0}};
    gn->keyed.erase(param); // an override is a constant
}

void set_param_text(Graph& graph, const NodeRegistry& registry, const std::string& node, const std::string& param,
                    const std::string& value_text, const std::string& origin) {
    GraphNode* gn = nullptr;
    const ParamDecl* d = nullptr;
    try {
        d = &find_override_target(graph, registry, node, param, gn);
    } catch (const Error& e) {
        throw Error(origin + ": " + e.what());
    }
    // A string parameter takes the text as it is; any other value, and a schema text
    // option given as a list ('--set p.sky_colour=[1,2,3]'), is read as a YAML flow value
    // by the graph file's own converter, so both front ends accept the same values.
    ParamValue v;
    std::string err;
    const bool list = !value_text.empty() && value_text.front() == '[';
    if (d->type == ParamType::String && !(d->check_value && list)) {
        v = value_text;
    } else {
        YAML::Node n;
        try {
            n = YAML::Load(value_text);
        } catch (const YAML::Exception& e) {
            throw Error(origin + ": cannot read value '" + value_text + "': " + e.msg);
        }
        err = detail::param_from_yaml(n, *d, v);
    }
    if (err.empty()) err = d->check(v);
    if (!err.empty())
        throw Error(origin + ": node '" + node + "': parameter '" + param + "' (" + std::string(param_type_name(d->type)) + "): " + err);
    gn->params[param] = {v, SourceLocation{origin, 0, 0}};
    gn->keyed.erase(param); // an override is a constant
}

ParamValue keyed_value(const ParamKeys& k, const ParamDecl& decl, double t) {
    if (k.keys.empty()) return decl.default_value;
    if (t <= k.keys.front().first) return k.keys.front().second;
    if (t >= k.keys.back().first) return k.keys.back().second;
    size_t i = 1;
    while (k.keys[i].first < t) ++i;
    const auto& [t0, v0] = k.keys[i - 1];
    const auto& [t1, v1] = k.keys[i];
    double u = (t - t0) / (t1 - t0);
    if (k.smooth) u = u * u * (3 - 2 * u);
    const bool integral = decl.type == ParamType::Int || decl.type == ParamType::Int2 || decl.type == ParamType::Int3;
    auto mix = [&](double a, double b) {
        const double x = a + (b - a) * u;
        return integral ? double(std::llround(x)) : x;
    };
    auto num = [](const ParamValue& v) { return std::holds_alternative<int64_t>(v) ? double(std::get<int64_t>(v)) : std::get<double>(v); };
    if (std::holds_alternative<std::vector<double>>(v0)) {
        const auto& a = std::get<std::vector<double>>(v0);
        const auto& b = std::get<std::vector<double>>(v1);
        std::vector<double> out(a.size());
        for (size_t c = 0; c < a.size(); ++c) out[c] = mix(a[c], b[c]);
        return out;
    }
    const double x = mix(num(v0), num(v1));
    if (decl.type == ParamType::Int) return int64_t(x);
    return x;
}

void set_graph_time(Graph& graph, const NodeRegistry& registry, double t) {
    if (!std::isfinite(t)) throw Error("graph time must be finite");
    for (GraphNode& n : graph.nodes) {
        if (n.keyed.empty()) continue;
        const NodeType* type = registry.find(n.type);
        for (const auto& [name, keys] : n.keyed) {
            const ParamDecl* d = type ? type->decl.find_param(name) : nullptr;
            if (!d) continue;
            n.params[name] = {keyed_value(keys, *d, t), keys.where};
        }
    }
    graph.current_time = t;
}

} // namespace atlas
