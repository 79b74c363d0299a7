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
//
// Implemented in graph_file.cpp, graph_validate.cpp (src/graph/).
#pragma once

#include "atlas/core/error.h"
#include "atlas/graph/node.h"

#include <cmath>
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

// A numeric parameter keyed over the graph's time (docs/graph-format.md, "Time"):
// `param: {keys: [[t0, v0], [t1, v1], ...], interp: linear|smooth}`, times in
// seconds, strictly increasing; before the first key the first value, after the
// last the last. Smooth eases each span with smoothstep; integers round to nearest.
struct ParamKeys {
    bool smooth = false;
    std::vector<std::pair<double, ParamValue>> keys;
    SourceLocation where;
};

struct GraphNode {
    std::string name;
    std::string type;
    SourceLocation where;
    std::map<std::string, ParamSetting> params; // explicitly set; defaults are not listed
    // Keyed parameters; params[name] holds the value at the graph's current time.
    std::map<std::string, ParamKeys> keyed;
    std::map<std::string, InputBinding> inputs;
};

// `time: {start: S, end: E, fps: F}`: the graph's time range in seconds and its
// frame rate. Frame f is at start + f / fps, f = 0 .. frames() - 1.
struct GraphTime {
    double start = 0, end = 0, fps = 1;
    SourceLocation where;
    int frames() const { return static_cast<int>(std::floor((end - start) * fps + 1e-9)) + 1; }
    double at_frame(int f) const { return start + double(f) / fps; }
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
    std::optional<GraphTime> time;  // `time:`, when the graph declares one
    double current_time = 0;        // what keyed parameters hold now (set_graph_time)

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

// The value of keyed parameter `keys` (declared `decl`) at time t.
ParamValue keyed_value(const ParamKeys& keys, const ParamDecl& decl, double t);
// Sets every keyed parameter to its value at time t (seconds). Nothing else
// changes, so a cook at another time re-cooks only the nodes that read a keyed
// parameter and what depends on them (their content hashes are unchanged).
void set_graph_time(Graph& graph, const NodeRegistry& registry, double t);

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
