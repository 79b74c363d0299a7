// atlas nodes [TYPE] [--markdown], atlas options [--markdown]
#include "cli.h"

#include "atlas/graph/graph.h"
#include "atlas/graph/node_docs.h"
#include "atlas/render/preview_options.h"

#include <iostream>

namespace atlas::cli {

int run_nodes(const Args& a) {
    NodeRegistry reg = builtin_nodes();
    if (a.has("--markdown")) {
        std::cout << node_reference_markdown(reg);
        return 0;
    }
    if (a.positional.empty()) {
        std::cout << node_list_text(reg);
        return 0;
    }
    for (const auto& name : a.positional) {
        const NodeType* t = reg.find(name);
        if (!t) {
            throw Error("unknown node type '" + name + "'" + name_hint(name, reg.names(), "known types"));
        }
        std::cout << node_reference_text(*t);
    }
    return 0;
}

// The Markdown is readable as text too: one generator, no second copy to drift.
int run_options(const Args& a) {
    if (!a.positional.empty()) throw UsageError{"expected no arguments", "options"};
    std::cout << options_reference_markdown() << render::preview_options_markdown();
    return 0;
}

} // namespace atlas::cli
