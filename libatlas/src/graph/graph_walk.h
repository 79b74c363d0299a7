// Internal to graph: walking a parsed graph (shared by the evaluator and the tiled cook).
#pragma once

#include "atlas/graph/graph.h"
#include "atlas/graph/node.h"

#include <functional>
#include <set>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace atlas::detail {

// A parameter value from YAML, as a graph file gives it (a list for float2/float3/
// int2/int3 and for a schema text option that takes numbers, else one scalar): the one
// converter of graph files and --set. Returns "" or what was expected.
std::string param_from_yaml(const YAML::Node& n, const ParamDecl& decl, ParamValue& out);

// Topological order (inputs first) of every node, following file order.
inline std::vector<const GraphNode*> topological_order(const Graph& g) {
    std::vector<const GraphNode*> order;
    std::set<std::string> done;
    std::function<void(const GraphNode&)> visit = [&](const GraphNode& n) {
        if (done.count(n.name)) return;
        done.insert(n.name);
        for (const auto& [port, b] : n.inputs) visit(*g.find(b.node));
        order.push_back(&n);
    };
    for (const auto& n : g.nodes) visit(n);
    return order;
}

// The output port an input binding reads: its own, or the source node's first output.
inline std::string source_port(const Graph& g, const NodeRegistry& reg, const InputBinding& b) {
    if (!b.port.empty()) return b.port;
    return reg.find(g.find(b.node)->type)->decl.outputs().front().name;
}

} // namespace atlas::detail
