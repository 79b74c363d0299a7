// The atlas command line: subcommands declared with their options, so that
// help and "did you mean" come from one table (in the manner of vdb_tool).
#pragma once

#include "atlas/core/option_schema.h"
#include "atlas/render/preview_options.h"

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace atlas {
class Session;
}

namespace atlas::cli {

struct OptionDecl {
    std::string name;   // "--out"
    std::string value;  // "DIR" (empty: a flag)
    std::string doc;
    bool repeatable = false;
};

// Parsed arguments of one subcommand.
struct Args {
    std::vector<std::string> positional;
    std::map<std::string, std::vector<std::string>> options; // name -> values ("" for flags)
    bool has(const std::string& name) const { return options.count(name) > 0; }
    std::string get(const std::string& name, const std::string& def = "") const {
        auto it = options.find(name);
        return it == options.end() || it->second.empty() ? def : it->second.back();
    }
    const std::vector<std::string>& all(const std::string& name) const {
        static const std::vector<std::string> none;
        auto it = options.find(name);
        return it == options.end() ? none : it->second;
    }
};

struct Command {
    std::string name;
    std::string usage;    // "GRAPH [options]"
    std::string summary;  // one line
    std::vector<OptionDecl> options;
    std::function<int(const Args&)> run;
};

// Thrown for a bad command line; main prints it with the usage and exits 2. A
// std::exception, so code that catches those does not lose it; main and the
// --watch loops catch it first.
struct UsageError : std::runtime_error {
    UsageError(std::string text, std::string cmd) : std::runtime_error(text), message(std::move(text)), command(std::move(cmd)) {}
    std::string message;
    std::string command; // the subcommand whose --help to suggest ("" = the command list)
};

const std::vector<Command>& commands();

// Applies every --set NODE.PARAM=VALUE of `a` to the session (`cmd` names the command in a usage
// error). With several graphs (`matched` given), a --set applies to the graphs that have its node,
// and the caller checks that each one matched some graph.
void apply_sets(Session& s, const Args& a, const std::string& cmd, std::set<std::string>* matched = nullptr);
// The on-disk cache a command uses: --cache DIR, else $ATLAS_CACHE_DIR unless --no-cache;
// none when neither. --cache with --no-cache is a usage error naming `cmd`.
std::optional<std::filesystem::path> cache_dir_flag(const Args& a, const std::string& cmd);
Args parse_args(const Command& cmd, const std::vector<std::string>& argv);
std::string command_help(const Command& cmd);
std::string general_help();

// A schema option's flag doc in help: its doc, and for names the accepted ones.
std::string schema_flag_doc(const TextOptionSpec& o);

// Sets `out` from the flags of `cmd` that schema options declare (a Flag option's
// flag takes no value and means true; a repeatable one's values are joined with ';');
// throws UsageError "--flag expects <expected>, got '<text>'" (a Text option adds why).
// Other flags are left to the caller.
template <class T>
void read_schema_flags(const Args& a, std::span<const TextOption<T>> schema, T& out, const std::string& cmd) {
    for (const TextOption<T>& o : schema) {
        if (!o.cli_flag || !a.has(o.cli_flag)) continue;
        std::string text = o.kind == OptionKind::Flag ? "true" : a.get(o.cli_flag);
        if (o.repeatable) {
            text.clear();
            for (const std::string& v : a.all(o.cli_flag)) text += (text.empty() ? "" : ";") + v;
        }
        if (!set_text_option(o, text, out)) {
            const std::string why = o.kind == OptionKind::Text && o.check_text ? ": " + o.check_text(text) : "";
            throw UsageError{std::string(o.cli_flag) + " expects " + o.expected() + ", got '" + text + "'" + why, cmd};
        }
    }
}

// Subcommand entry points (one file each).
int run_cook(const Args&);
int run_validate(const Args&);
int run_cache(const Args&);
int run_nodes(const Args&);
int run_options(const Args&);
int run_info(const Args&);
int run_preview(const Args&);
int run_view(const Args&);

// The preview's render flags (--size, --camera, --sun, ...), checked; errors name
// `command` (cmd_preview.cpp).
render::PreviewOptions read_preview_flags(const Args& a, const char* command);
int run_compress(const Args&);
int run_decompress(const Args&);

} // namespace atlas::cli
