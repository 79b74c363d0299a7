// atlas/graph/evaluator.h - cooking a graph: lazy, hashed, cached, parallel.
//
// Cooking pulls only what the requested outputs need (a node no requested
// output depends on is never cooked). Each node's content hash covers its
// type, version, resolved parameters, hash_extra and its inputs' hashes;
// results are cached by hash in memory (per Session) and optionally on disk.
// Independent nodes cook in parallel inside a TBB arena of `jobs` threads;
// results do not depend on the thread count.
#pragma once

#include "atlas/core/hash.h"
#include "atlas/core/progress.h"
#include "atlas/graph/graph.h"

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace atlas {

struct CookOptions {
    // Outputs to produce, by file name or node name; empty = every output.
    std::vector<std::string> outputs;
    int jobs = 0;                                // 0 = all hardware threads
    bool checked = false;                        // re-cook everything and compare with the cache
    std::optional<std::filesystem::path> cache_dir; // on-disk cache; none when empty
    uint64_t memory_budget = MemoryBudget::kDefaultLimit;
    std::filesystem::path out_dir = ".";
    bool allow_outside_out = false;              // permit absolute / escaping output paths
    bool write_outputs = true;                   // false: cook values only (hosts, tests)
    ProgressSink progress;
};

// Per-node record of a cook. Keys and meanings are documented in docs/report.md.
struct NodeReport {
    std::string type;
    std::string status; // "cooked", "cached" or "skipped"
    std::string reason; // why cached/skipped, e.g. "memory cache", "not needed by the requested outputs"
    std::string hash;   // hex; empty when skipped
    double seconds = 0;
    uint64_t bytes = 0; // size of the node's output values
    std::map<std::string, double> metrics;
    std::vector<std::string> warnings;
};

struct OutputReport {
    std::string node, port, file, format;
    std::vector<std::filesystem::path> written;
    std::map<std::string, double> metrics; // what the writer measured, e.g. a DDS encode's errors
};

struct CookResult {
    std::map<std::string, NodeReport> nodes;
    std::vector<OutputReport> outputs;
    double seconds = 0;
    int jobs = 1;
    bool checked = false;

    std::vector<std::string> with_status(const std::string& status) const;
    // The --report JSON document (stable keys, see docs/report.md).
    std::string to_json(const std::string& graph_file) const;
};

class ValueCache; // in-memory cache, keyed by node hash

// A loaded graph plus its in-memory cache: the embedding API. A host keeps
// one Session per open graph, edits parameters and re-cooks; only what
// changed is cooked again. Not thread-safe: one cook at a time per Session.
class Session {
public:
    explicit Session(NodeRegistry registry);
    ~Session();
    Session(Session&&) noexcept;
    Session& operator=(Session&&) noexcept;

    void load(const std::filesystem::path& graph_file);
    void load_text(const std::string& text, const std::string& name, const std::filesystem::path& base_dir);
    const Graph& graph() const;
    const NodeRegistry& registry() const { return registry_; }

    // Parameter overrides (validated; throw atlas::Error).
    void set(const std::string& node, const std::string& param, const ParamValue& value);
    void set_text(const std::string& node, const std::string& param, const std::string& text);

    // Cooks the requested outputs and writes them (atomically: a failed cook
    // writes nothing). Throws atlas::Error (CancelledError on cancel).
    CookResult cook(const CookOptions& options);
    // Cooks just what one node output needs and returns its value.
    Value get(const std::string& node, const std::string& port, const CookOptions& options = {});

    // Content hash of every node (for tests and tools).
    std::map<std::string, Hash128> node_hashes() const;

private:
    CookResult run(const CookOptions& options, const std::vector<std::pair<std::string, std::string>>* want_value,
                   std::vector<Value>* values_out);
    NodeRegistry registry_;
    std::unique_ptr<Graph> graph_;
    std::unique_ptr<ValueCache> cache_;
    std::map<std::string, Hash128> last_hashes_; // node -> hash when last needed
};

} // namespace atlas
