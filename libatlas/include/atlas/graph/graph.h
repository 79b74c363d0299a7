// atlas/graph/graph.h - graph files: parsing, validation, parameter overrides.
//
// A graph file is YAML (see docs/graph-format.md):
//
//   atlas: 1
//   nodes:
//     base:   { type: noise/value, params: { frequency: 4 } }
//     shaped: { type: math/remap, inputs: { in: base }, params: { out_max: 2 } }
//   outputs:
//     - { node: shaped, port: out, file: density.exr }
//
// Every error is a ParseError naming file:line:col and what was expected.
#pragma once

#include "atlas/core/error.h"
#include "atlas/graph/node.h"

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace atlas {

constexpr int kGraphFormatVersion = 1;

struct InputBinding {
    std::string node; // source node name
    std::string port; // source output port
    SourceLocation where;
};

struct ParamSetting {
    ParamValue value;
    SourceLocation where;
};

struct GraphNode {
    std::string name;
    std::string type;
    SourceLocation where;
    std::map<std::string, ParamSetting> params; // explicitly set; defaults are not listed
    std::map<std::string, InputBinding> inputs;
};

struct GraphOutput {
    std::string node;
    std::string port;
    std::string file;   // relative to the output directory
    std::string format; // resolved (from the extension when not given)
    std::map<std::string, std::string> options;
    SourceLocation where;
};

// `requires:` - files this graph reads that another graph writes. `atlas cook`
// cooks that graph into `out` first when an input file under `out` is missing
// (Session::cook_requirements), so a fresh clone cooks (docs/graph-format.md).
struct GraphRequirement {
    std::filesystem::path graph; // resolved against the graph's folder
    std::filesystem::path out;   // the folder that graph's cook writes, resolved likewise
    SourceLocation where;
};

struct Graph {
    std::filesystem::path file;     // the graph file ("" when parsed from text)
    std::filesystem::path base_dir; // relative input paths resolve against this
    int version = kGraphFormatVersion;
    std::vector<GraphNode> nodes;   // in file order
    std::vector<GraphOutput> outputs;
    std::vector<GraphRequirement> requirements;
    // `budget: {texture_mb: N}`: the most GPU texture memory (DDS outputs, MB = 10^6
    // bytes, as the talks count) the graph's outputs may take; a cook over it fails
    // before committing anything, naming the largest textures.
    std::optional<double> texture_budget_mb;
    SourceLocation budget_where;

    const GraphNode* find(const std::string& name) const;
    GraphNode* find(const std::string& name);
};

// Parses and validates (types, ranges, connections, cycles, outputs).
Graph load_graph(const std::filesystem::path& file, const NodeRegistry& registry);
Graph parse_graph(const std::string& text, const std::string& filename, const std::filesystem::path& base_dir,
                  const NodeRegistry& registry);

// Re-validates a graph (after edits through set_param or by a host).
void validate_graph(const Graph& graph, const NodeRegistry& registry);

// Overrides NODE.PARAM from text as the CLI's --set gives it ("4", "true",
// "[1,2,3]", "name"). Checks type and range; throws atlas::Error that names
// `origin` (e.g. "--set clouds.seed=x") on failure.
void set_param_text(Graph& graph, const NodeRegistry& registry, const std::string& node, const std::string& param,
                    const std::string& value_text, const std::string& origin);
// The same with a typed value (for host programs).
void set_param(Graph& graph, const NodeRegistry& registry, const std::string& node, const std::string& param,
               const ParamValue& value);

// The resolved parameter values of a node (explicit over defaults), as a proxy
// cook of factor `proxy` uses them (ParamDecl::at_proxy; 1: as written).
std::map<std::string, ParamValue> resolved_params(const GraphNode& node, const NodeType& type, int proxy = 1);

// "did you mean 'amount'?" helper: the closest candidate within a small edit
// distance, or "".
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

// The tail of an "unknown name" message: " (did you mean 'x'?)" when a
// candidate is close, else " (<intro>: a, b, c)", or "" with no candidates.
std::string name_hint(const std::string& word, const std::vector<std::string>& candidates, const std::string& intro = "expected one of");

} // namespace atlas
