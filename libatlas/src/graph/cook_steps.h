// Internal to graph: the steps of a cook that the evaluator (Session::run, evaluator.cpp)
// and the tiled cook (tiling.cpp) share, named as docs/architecture.md names them:
// plan (which outputs), resolve (which nodes, in order), cook (one node), write (where
// and how an output's files go). Implemented in cook_steps.cpp.
#pragma once

#include "atlas/graph/graph.h"
#include "atlas/graph/node.h"
#include "atlas/core/files.h"
#include "atlas/core/hash.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace atlas::detail {

// Plan: the graph's outputs a cook writes: all of them, or those named (by file or by
// node) in `wanted`. An unknown name is an error that lists what the graph writes.
std::vector<const GraphOutput*> select_outputs(const Graph& g, const std::vector<std::string>& wanted);

// Resolve: every node the `targets` depend on (themselves included), inputs first, in
// the graph's topological order.
std::vector<const GraphNode*> needed_nodes(const Graph& g, const std::vector<std::string>& targets);

// Cook: one node on its inputs. The node's own progress and Ctrl-C go through
// `progress`; `window` is a tiled cook's window (null otherwise). Throws what the node
// throws, unprefixed (each caller names the node its own way); a node that leaves an
// output unset is an internal error.
struct NodeRun {
    std::map<std::string, Value> outputs;
    std::map<std::string, double> metrics;
    std::vector<std::string> warnings;
    double seconds = 0;
};
NodeRun cook_node(const GraphNode& n, const NodeType& type, const NodeParams& params, std::map<std::string, Value> inputs,
                  const MemoryBudget& budget, const ProgressSink& progress, const TileWindow* window = nullptr);

// Write: where an output's files land. `root / rel` is the output's file; an output
// outside `out_dir` (allowed with `allow_outside`) is rooted at its own folder. Throws
// for a destination that may not be written (check_destination with `protect`).
struct OutputPlace {
    std::filesystem::path root, rel;
};
OutputPlace output_place(const std::filesystem::path& out_dir, const GraphOutput& o, bool allow_outside,
                         const std::vector<ProtectedFile>& protect = {});

// Write: an output's spec (format and writer versions, port, format, its path `name` as
// placed, options; hex) and its key (the spec and the source node's content hash), by
// which the output records (output_records.h) know its files on disk. The tiled cook's
// assembled outputs use the same key: their bytes are the untiled cook's.
struct OutputSpec {
    std::string spec;
    Hash128 key;
};
OutputSpec output_spec(const GraphOutput& o, const std::string& name, const Hash128& node_hash);

// Write: the message of an output that failed to write: its place in the graph file,
// then the writer's message, naming the output once (writers usually name it already).
std::string output_error(const GraphOutput& o, const std::string& message);

} // namespace atlas::detail
