// libFuzzer: graph files. Any input either parses or throws atlas::Error
// (ParseError for the file's own mistakes); anything else is a bug.
#include "atlas/graph/graph.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const atlas::NodeRegistry registry = atlas::builtin_nodes();
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        atlas::Graph g = atlas::parse_graph(text, "fuzz.yaml", "/nonexistent", registry);
        // Overrides go through the same checks.
        for (const auto& n : g.nodes)
            for (const auto& [name, p] : n.params) {
                try {
                    atlas::set_param_text(g, registry, n.name, name, text.substr(0, 64), "--set");
                } catch (const atlas::Error&) {
                }
            }
    } catch (const atlas::Error&) {
    }
    return 0;
}
