// atlas: build the command table, run one subcommand, turn errors into an exit status.
#include "cli.h"

#include "atlas/core/error.h"
#include "atlas/graph/graph.h"

#include <csignal>
#include <iostream>
#include <malloc.h>

int main(int argc, char** argv) {
    using namespace atlas::cli;
    std::vector<std::string> args(argv + 1, argv + argc);
    // Past a file-size limit (ulimit -f) a write fails with EFBIG and the writer
    // says so, instead of the default SIGXFSZ killing the program mid-write.
    std::signal(SIGXFSZ, SIG_IGN);
    // A cook frees and makes buffers of a few to 32 MiB over and over (SDF scratch,
    // encoder slabs, writers' strips): kept in the heap instead of glibc's default of
    // mapping and unmapping each, they are not faulted in and zeroed by the kernel
    // again (cloudscape: 1.7 -> 1.0 s of system time). A process-wide choice, so the
    // program's and not the library's (a host keeps its own allocator settings).
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
    try {
        if (args.empty() || args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
            if (args.size() >= 2) {
                for (const auto& c : commands())
                    if (c.name == args[1]) { std::cout << command_help(c); return 0; }
            }
            std::cout << general_help();
            return args.empty() ? 2 : 0;
        }
        if (args[0] == "--version") { std::cout << "atlas " ATLAS_VERSION_STRING "\n"; return 0; }
        for (const auto& c : commands()) {
            if (c.name != args[0]) continue;
            Args parsed = parse_args(c, {args.begin() + 1, args.end()});
            if (parsed.has("--help")) { std::cout << command_help(c); return 0; }
            return c.run(parsed);
        }
        std::vector<std::string> names;
        for (const auto& c : commands()) names.push_back(c.name);
        throw UsageError{"unknown command '" + args[0] + "'" + atlas::name_hint(args[0], names, "commands"), ""};
    } catch (const UsageError& e) {
        std::cerr << "atlas: error: " << e.message << "\n";
        if (!e.command.empty()) std::cerr << "run 'atlas " << e.command << " --help' for its options\n";
        else std::cerr << "run 'atlas --help' for the list of commands\n";
        return 2;
    } catch (const atlas::CancelledError&) {
        std::cerr << "atlas: cancelled; no output was written\n";
        return 130;
    } catch (const std::exception& e) {
        // A located error already reads "FILE:LINE:COL: error: ..." (the
        // compiler form editors jump to): say "error" once.
        const std::string msg = e.what();
        std::cerr << (msg.find(": error: ") != std::string::npos ? "" : "atlas: error: ") << msg << "\n";
        return 1;
    }
}
