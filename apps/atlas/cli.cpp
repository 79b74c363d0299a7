#include "cli.h"

#include "atlas/compress/compress_options.h"
#include "atlas/compress/texture.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/graph.h"
#include "atlas/render/preview_options.h"
#include "atlas/render/renderer.h"

#include <cstdlib>
#include <sstream>

namespace atlas::cli {

namespace {
// `head`, then one flag per schema option that has one (in the schema's order), then `tail`.
template <class T>
std::vector<OptionDecl> with_schema_flags(std::vector<OptionDecl> head, std::span<const TextOption<T>> schema, std::vector<OptionDecl> tail) {
    for (const TextOption<T>& o : schema)
        if (o.cli_flag) head.push_back({o.cli_flag, o.metavar, schema_flag_doc(o), o.repeatable});
    head.insert(head.end(), tail.begin(), tail.end());
    return head;
}
// The preview's: `head`, its schema flags, the spellings that set several options, `tail`.
std::vector<OptionDecl> with_preview_flags(std::vector<OptionDecl> head, std::vector<OptionDecl> tail) {
    head = with_schema_flags(std::move(head), render::preview_options(), {});
    for (const auto& sp : render::preview_cli_spellings()) head.push_back({sp.cli_flag, sp.metavar, sp.doc});
    head.insert(head.end(), tail.begin(), tail.end());
    return head;
}
} // namespace

std::string schema_flag_doc(const TextOptionSpec& o) {
    const bool names = o.kind == OptionKind::Choice || o.kind == OptionKind::List;
    return o.doc + (names && !o.words.empty() ? ": " + o.expected() : "") + (o.default_text.empty() ? "" : " (default " + o.default_text + ")") +
           (o.repeatable ? "; repeatable" : "");
}

const std::vector<Command>& commands() {
    static const std::vector<Command> table = {
        {"cook", "GRAPH... [options]", "cook graph files (sharing one cache and one report) and write their outputs",
         {{"--out", "DIR", "output directory; graph output paths are relative to it (default: .)"},
          {"--output", "NAME", "cook only this output (file name or node name); repeatable", true},
          {"--set", "NODE.PARAM=VALUE", "override a parameter; repeatable", true},
          {"--jobs", "N", "worker threads (default: all cores); output bytes do not depend on it"},
          {"--cache", "DIR", "on-disk cache of node results (re-cooks only what changed)"},
          {"--no-cache", "", "do not read or write the on-disk cache"},
          {"--cache-max-size", "SIZE", "after the cook, prune the cache to SIZE, least recently used first"},
          {"--report", "FILE.json", "write the cook report (nodes, inputs and outputs with hashes; also for a failed cook)"},
          {"--depfile", "FILE", "write a Make/Ninja depfile: the output files depend on the graphs and every file they read"},
          {"--rewrite", "", "write every output even when its file on disk is up to date"},
          {"--keep-going", "", "an output whose writer fails is reported and skipped; the other outputs are written"},
          {"--memory-budget", "SIZE", "refuse allocations past this size (default 8GiB)"},
          {"--checked", "", "re-cook every node and compare with the cache (catches incomplete hashes)"},
          {"--allow-outside-out", "", "allow output paths that are absolute or leave --out"},
          {"--frames", "A:B|N|all", "the graph's time sequence (its time: block): frame f into OUT/frame_NNNN/ with keyed parameters at start + f / fps, then OUT/frames.json (docs/graph-format.md, \"Time\")"},
          {"--tiles", "NX,NY", "cook in NX x NY tiles of the XY grid: tile files and OUT/tiles/index.json (docs/scale.md)"},
          {"--tile", "I,J", "with --tiles: cook only tile I,J (0-based; for a cluster worker)"},
          {"--assemble", "", "with --tiles: also write the untiled outputs from the tiles (the bytes one cook writes)"},
          {"--no-tile-values", "", "with --tiles: tiles keep only their files, not an exact copy of their values (nothing to --assemble from)"},
          {"--quiet", "", "no progress or summary on stderr (warnings still print)"}},
         run_cook},
        {"validate", "GRAPH [--set NODE.PARAM=VALUE]...", "parse and type-check a graph; cook nothing",
         {{"--set", "NODE.PARAM=VALUE", "override a parameter; repeatable", true}},
         run_validate},
        {"cache", "prune [DIR] --max-size SIZE", "remove least recently used cache entries until DIR (default ATLAS_CACHE_DIR) holds at most SIZE",
         {{"--max-size", "SIZE", "bytes to keep, e.g. 2GiB (0 empties the cache)"},
          {"--quiet", "", "no summary on stderr"}},
         run_cache},
        {"nodes", "[TYPE] [--markdown]", "list node types, or show one node's ports and parameters",
         {{"--markdown", "", "print the whole reference as Markdown (docs/nodes.md)"}},
         run_nodes},
        {"options", "[--markdown]", "list every output format's options, the compress options (atlas compress flags = dds options) and the preview options (atlas preview flags = render/preview parameters)",
         {{"--markdown", "", "print the reference as Markdown (docs/options.md)"}},
         run_options},
        {"compress", "IN -o OUT.dds --format FORMAT [options]",
         "encode a field file (EXR, PNG, TGA, VDB, a slice stack STEM.001.tga or STEM(0).tga) as a DDS texture with a guaranteed error bound",
         with_schema_flags({{"--out", "OUT.dds", "output texture (also -o); OUT.dds.json (the manifest) is written beside it"}}, compress::compress_options(), {
          {"--verify", "", "decode the written file with every decoder model and print the errors (default after a bounded encode)"},
          {"--no-verify", "", "skip the verification after a bounded encode"},
          {"--sweep", "", "encode at every quality level and print error against time as CSV (no texture written)"},
          {"--csv", "FILE", "with --sweep: also write the table to FILE"},
          {"--report", "FILE.json", "write the compression report"},
          {"--memory-budget", "SIZE", "refuse inputs past this size (default 8GiB)"},
          {"--quiet", "", "no progress bar"}}),
         run_compress},
        {"decompress", "IN.dds -o OUT.exr [--decoder MODEL]", "decode a DDS texture to float (EXR, PNG, VDB, ...)",
         {{"--out", "OUT", "output file; the format follows the extension"},
          {"--decoder", "MODEL", "decoder model: " + compress::decoder_names() + " (default reference)"}},
         run_decompress},
        {"info", "FILE...", "describe EXR, VDB, image or TGA-slice files: size, channels, value statistics", {}, run_info},
        {"preview", "(GRAPH | FILES...) -o OUT.png [options]",
         "render what a graph writes (NDF set: 2.5D cloud layer over a curved Earth; NVDF set: voxel clouds; both: composited) or NVDF files",
         with_preview_flags({{"--out", "OUT.png", "output picture (also -o): PNG tone-mapped, .exr linear radiance + transmittance"}}, {
          {"--noise", "FILE|auto|nubis|none", "voxel up-rez noise: a 4-channel volume file, nubis (noise/nubis_set 128^3 cooked through the cache), auto (default: nubis for an NVDF set, none for a plain density grid, which has its own detail) or none"},
          {"--voxel", "M", "voxel size in metres for files without bounds (TGA stacks)"},
          {"--sweep", "", "print fast-mode time and RMSE vs the reference per quality as CSV; -o writes the reference"},
          {"--turntable", "N", "N frames around the volume: OUT_000.png .."},
          {"--cache", "DIR", "on-disk cache of node results when previewing a graph (as atlas cook)"},
          {"--no-cache", "", "do not use ATLAS_CACHE_DIR"},
          {"--jobs", "N", "worker threads (default: all cores); the picture does not depend on it"},
          {"--mode", "layer|voxel", "override the mode picked from the graph's outputs (default: NDF set -> layer, NVDF -> voxel, both -> composited)"},
          {"--set", "NODE.PARAM=VALUE", "override a parameter before cooking (as atlas cook); repeatable", true},
          {"--proxy", "P", "cook the graph at 1/P of its grid cells per axis over the same bounds (4: a quarter), for a quick look; nodes' proxy behaviour in docs/nodes.md (default 1: full)"},
          {"--watch", "", "after the preview, re-cook and re-render whenever the graph or a file it reads changes, keeping what was cooked in memory (prints each step's time)"},
          {"--watch-max", "N", "with --watch: stop after N re-renders"},
          {"--frames", "N", "a time sequence OUT_000.png ..: frame i at --time + i x --time-step (wind scroll) with flash index --flash + i"},
          {"--time-step", "S", "seconds between --frames (default 60)"},
          {"--slice", "K", "2.5D: draw time slice K of the graph's ndf/forecast maps (--frames steps one slice per frame)"},
          {"--animation", "FILE.webp", "with --frames or --turntable: also the sequence as one animated WebP (docs/render.md, \"Sequences\")"},
          {"--fps", "N", "the animation's frames per second (default 12)"},
          {"--animation-quality", "Q", "WebP quality 0..100, or 101 for lossless (default 90)"},
          {"--contact-sheet", "FILE", "with --frames or --turntable: also every frame on one picture, left to right, top to bottom (at most 1920 pixels wide)"},
          {"--export-scene", "DIR", "also write DIR/density.vdb and DIR/scene.json for scripts/cycles_reference.py (Blender Cycles)"},
          {"--quiet", "", "no progress bar or summary"}}),
         run_preview},
        {"view", "GRAPH [-o DIR] [options]",
         "write the graph's 2.5D cloudscape (its NDF set) as a page @takram/three-clouds draws in real time, and open it (docs/web.md)",
         with_preview_flags({{"--out", "DIR", "the page's folder (also -o; default GRAPH_view beside the working directory)"}}, {
          {"--no-open", "", "write the page, do not open a browser"},
          {"--cache", "DIR", "on-disk cache of node results (as atlas cook)"},
          {"--no-cache", "", "do not use ATLAS_CACHE_DIR"},
          {"--set", "NODE.PARAM=VALUE", "override a parameter before cooking (as atlas cook); repeatable", true},
          {"--quiet", "", "no progress bar or summary"}}),
         run_view},
    };
    return table;
}

Args parse_args(const Command& cmd, const std::vector<std::string>& argv) {
    Args a;
    for (size_t i = 0; i < argv.size(); ++i) {
        std::string arg = argv[i];
        if (arg == "-h" || arg == "--help") { a.options["--help"].push_back(""); continue; }
        if (arg.size() > 1 && arg[0] == '-') {
            std::string name = arg, value;
            bool inline_value = false;
            if (auto eq = arg.find('='); eq != std::string::npos && arg.rfind("--", 0) == 0) {
                name = arg.substr(0, eq);
                value = arg.substr(eq + 1);
                inline_value = true;
            }
            if (name == "-o") name = "--out";
            const OptionDecl* decl = nullptr;
            std::vector<std::string> names;
            for (const auto& o : cmd.options) {
                names.push_back(o.name);
                if (o.name == name) decl = &o;
            }
            if (!decl) {
                throw UsageError{"unknown option '" + name + "' for 'atlas " + cmd.name + "'" + name_hint(name, names, "options"), cmd.name};
            }
            if (!decl->value.empty() && !inline_value) {
                if (i + 1 >= argv.size()) throw UsageError{"option '" + name + "' expects a value " + decl->value, cmd.name};
                value = argv[++i];
            } else if (decl->value.empty() && inline_value) {
                throw UsageError{"option '" + name + "' takes no value", cmd.name};
            }
            if (!decl->repeatable && a.options.count(name)) throw UsageError{"option '" + name + "' given twice", cmd.name};
            a.options[name].push_back(value);
        } else {
            a.positional.push_back(arg);
        }
    }
    return a;
}

std::string command_help(const Command& cmd) {
    std::ostringstream out;
    out << "usage: atlas " << cmd.name << " " << cmd.usage << "\n\n" << cmd.summary << "\n";
    if (!cmd.options.empty()) out << "\noptions:\n";
    for (const auto& o : cmd.options) {
        std::string left = "  " + o.name + (o.value.empty() ? "" : " " + o.value);
        out << left << std::string(left.size() < 30 ? 30 - left.size() : 1, ' ') << o.doc << "\n";
    }
    return out.str();
}

std::string general_help() {
    std::ostringstream out;
    out << "atlas - author volumetric cloud data (noises, NDFs, NVDFs, SDFs, BC textures)\n\n"
        << "usage: atlas COMMAND [options]\n\ncommands:\n";
    for (const auto& c : commands()) out << "  " << c.name << std::string(12 - c.name.size(), ' ') << c.summary << "\n";
    out << "\nrun 'atlas COMMAND --help' for a command's options. Messages and progress go to\n"
        << "stderr; stdout carries only data. Exit status: 0 ok, 1 error, 2 usage, 130 cancelled.\n";
    return out.str();
}

void apply_sets(Session& s, const Args& a, const std::string& cmd, std::set<std::string>* matched) {
    for (const auto& kv : a.all("--set")) {
        auto eq = kv.find('=');
        auto dot = kv.find('.');
        if (eq == std::string::npos || dot == std::string::npos || dot > eq)
            throw UsageError{"--set expects NODE.PARAM=VALUE, got '" + kv + "'", cmd};
        if (matched && !s.graph().find(kv.substr(0, dot))) continue;
        s.set_text(kv.substr(0, dot), kv.substr(dot + 1, eq - dot - 1), kv.substr(eq + 1));
        if (matched) matched->insert(kv);
    }
}

std::optional<std::filesystem::path> cache_dir_flag(const Args& a, const std::string& cmd) {
    if (a.has("--cache") && a.has("--no-cache")) throw UsageError{"--cache and --no-cache contradict each other", cmd};
    if (a.has("--cache")) return std::filesystem::path(a.get("--cache"));
    if (const char* env = std::getenv("ATLAS_CACHE_DIR"); env && *env && !a.has("--no-cache")) return std::filesystem::path(env);
    return std::nullopt;
}

} // namespace atlas::cli
