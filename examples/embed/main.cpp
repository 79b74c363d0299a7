// A host program embedding Atlas, as an editor plugin would: load a graph,
// cook it, change one parameter, re-cook incrementally and see what ran.
// Nothing here exits on error or prints from the library: errors are
// exceptions, progress and cancellation are callbacks.
#include "atlas/graph/evaluator.h"

#include <iostream>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: atlas_embed_example GRAPH\n";
        return 2;
    }
    try {
        atlas::Session session(atlas::builtin_nodes());
        session.load(argv[1]);

        atlas::CookOptions options;
        options.write_outputs = false; // a host usually wants values, not files
        options.progress.on_progress = [](const atlas::ProgressEvent& e) {
            (void)e; // a real host would update its status bar here (may be called from worker threads)
        };
        options.progress.is_cancelled = [] { return false; };

        atlas::CookResult first = session.cook(options);
        std::cout << "first cook: cooked " << first.with_status("cooked").size() << " nodes\n";

        // The artist drags a slider: only 'coverage' and what depends on it re-cook.
        session.set("coverage", "in_min", 0.5);
        atlas::CookResult second = session.cook(options);
        std::cout << "re-cooked:";
        for (const auto& name : second.with_status("cooked")) std::cout << " " << name;
        std::cout << "\nfrom cache:";
        for (const auto& name : second.with_status("cached")) std::cout << " " << name;
        std::cout << "\n";

        atlas::Value v = session.get("coverage", "out", options);
        auto field = std::get<atlas::Field3DPtr>(v);
        std::cout << "coverage field: " << field->nx() << "x" << field->ny() << "x" << field->nz() << "\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 1;
    }
}
