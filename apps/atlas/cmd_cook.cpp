// atlas cook / atlas validate.
#include "cli.h"
#include "progress_bar.h"

#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/core/memory.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/tiling.h"
#include "atlas/io/output_options.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

namespace atlas::cli {

namespace {
std::string one_graph(const Args& a, const std::string& cmd) {
    if (a.positional.size() != 1) throw UsageError{"expected one graph file, got " + std::to_string(a.positional.size()), cmd};
    return a.positional[0];
}
} // namespace

namespace {
// Make/Ninja depfile escaping: spaces and '#' with a backslash, '$' doubled.
std::string depfile_escape(const std::string& path) {
    std::string out;
    for (char c : path) {
        if (c == ' ' || c == '#' || c == '\\') out += '\\';
        if (c == '$') out += '$';
        out += c;
    }
    return out;
}

// What a report or depfile must never replace: the graph files, every input
// the cooks read and every file they wrote (checked as files: links caught).
std::vector<ProtectedFile> cook_files(const Args& a, const std::vector<std::pair<std::string, CookResult>>& cooks) {
    std::vector<ProtectedFile> v;
    for (const auto& g : a.positional) v.push_back({g, "a graph file of the cook"});
    for (const auto& [file, r] : cooks) {
        for (const auto& in : r.inputs) v.push_back({in.path, "an input file of the cook"});
        for (const auto& out : r.outputs)
            for (const auto& f : out.files) v.push_back({f.path, "an output of the cook"});
    }
    return v;
}

// --report and --depfile: a name of Atlas's own, a link, a device or a file
// of the cook is refused (before the cook with what is known then, and again
// when written).
void check_side_file(const Args& a, const std::string& flag, const std::vector<ProtectedFile>& protect) {
    if (!a.has(flag)) return;
    const std::filesystem::path p = a.get(flag);
    if (is_reserved_name(p.filename().string()))
        throw Error(p.string() + ": " + flag + " names a file Atlas keeps for its own records ('.atlas-...'); choose another name");
    check_destination(p, protect, flag.substr(2) + " file");
}

void write_text_atomic(const std::string& path, const std::string& text, const std::string& what, const std::vector<ProtectedFile>& protect) {
    write_file_atomic(
        path,
        [&](const std::filesystem::path& tmp) {
            try {
                write_file_checked(tmp, text.data(), text.size());
            } catch (const Error& e) {
                throw Error(path + ": cannot write " + what + " (" + e.what() + ")");
            }
        },
        protect);
}
} // namespace

namespace {
// "NX,NY" / "I,J" of --tiles and --tile.
Vec2i parse_pair(const Args& a, const std::string& flag, int min) {
    const std::string v = a.get(flag);
    const auto comma = v.find(',');
    try {
        size_t u0 = 0, u1 = 0;
        if (comma == std::string::npos) throw 0;
        const int x = std::stoi(v.substr(0, comma), &u0), y = std::stoi(v.substr(comma + 1), &u1);
        if (u0 != comma || u1 != v.size() - comma - 1 || x < min || y < min) throw 0;
        return {{x, y}};
    } catch (...) {
        throw UsageError{flag + " expects two integers >= " + std::to_string(min) + " as X,Y, got '" + v + "'", "cook"};
    }
}

// The tiled cook's files a report must not replace: the graph and every file written.
std::vector<ProtectedFile> tiled_files(const Args& a, const TiledCookResult& r) {
    std::vector<ProtectedFile> v = cook_files(a, {});
    for (const auto& p : r.written) v.push_back({p, "an output of the cook"});
    return v;
}

// atlas cook GRAPH --tiles NX,NY [--tile I,J] [--assemble] (docs/scale.md).
int run_cook_tiled(const Args& a, CookOptions o) {
    if (a.positional.size() != 1) throw UsageError{"--tiles cooks one graph file, got " + std::to_string(a.positional.size()), "cook"};
    if (!a.has("--tiles")) throw UsageError{"--tile and --assemble need --tiles NX,NY", "cook"};
    if (a.has("--depfile")) throw UsageError{"--depfile is not supported with --tiles (the tile index lists every file)", "cook"};
    TileOptions t;
    t.tiles = parse_pair(a, "--tiles", 1);
    if (a.has("--tile")) t.only = parse_pair(a, "--tile", 0);
    t.assemble = a.has("--assemble");
    t.exact_values = !a.has("--no-tile-values");
    if (t.only && t.assemble) throw UsageError{"--assemble needs every tile: it cannot be combined with --tile", "cook"};
    t.graph_name = a.positional[0];
    check_side_file(a, "--report", cook_files(a, {}));
    Session session(builtin_nodes());
    session.load(a.positional[0]);
    apply_sets(session, a, "cook");
    o.outputs = a.all("--output");
    ProgressBar bar(!a.has("--quiet"));
    o.progress = bar.sink();
    TiledCookResult r;
    try {
        cook_tiled(session, o, t, r);
    } catch (const std::exception& e) {
        bar.finish();
        // A failed tile's report: the tiles before it, and it with its error.
        if (a.has("--report"))
            write_text_atomic(a.get("--report"),
                              tiled_report_json(r, a.positional[0], dynamic_cast<const CancelledError*>(&e) ? "cancelled" : "failed", e.what()),
                              "the report", tiled_files(a, r));
        throw;
    }
    bar.finish();
    for (const auto& w : r.warnings) std::cerr << "warning: " << w << "\n";
    if (a.has("--report")) write_text_atomic(a.get("--report"), tiled_report_json(r, a.positional[0], "ok", ""), "the report", tiled_files(a, r));
    size_t cooked = 0;
    for (const auto& tr : r.tiles_done) cooked += tr.status == "cooked";
    std::cout << "cooked " << cooked << " of " << r.tiles_done.size() << " tiles (" << r.tiles[0] << " x " << r.tiles[1] << " over " << r.grid[0]
              << " x " << r.grid[1] << " texels) in " << r.seconds << " s; wrote " << r.written.size() << " files to " << o.out_dir.string() << "\n";
    for (const auto& p : r.written) std::cout << p.string() << "\n";
    return 0;
}
// A field's content hash per channel (none for other values): what frames.json
// compares between frames.
std::vector<Hash128> channel_hashes(const Value& v) {
    std::vector<Hash128> h;
    auto add = [&](const auto& field) {
        for (int c = 0; c < field.channels(); ++c) h.push_back(Hasher().add_floats(field.channel(c)).finish());
    };
    if (const auto* f3 = std::get_if<Field3DPtr>(&v); f3 && *f3) add(**f3);
    if (const auto* f2 = std::get_if<Field2DPtr>(&v); f2 && *f2) add(**f2);
    return h;
}

// A frame's output value in frames.json: a field's world bounds and the
// channels the file holds (`wanted`, its `channels` option; empty: all), each
// with whether its hash differs from `before` (the frame before's; null in the
// first frame, where every channel counts as changed).
void describe_field_value(const Value& v, const std::vector<std::string>& wanted, const std::vector<Hash128>& now,
                          const std::vector<Hash128>* before, nlohmann::json& entry) {
    auto describe = [&](const auto& field, std::vector<double> lo, std::vector<double> hi) {
        entry["bounds"] = {{"min", lo}, {"max", hi}};
        nlohmann::json channels = nlohmann::json::array();
        for (int c = 0; c < field.channels(); ++c) {
            const std::string& name = field.channel_names()[size_t(c)];
            if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), name) == wanted.end()) continue;
            const bool changed = !before || before->size() != now.size() || !((*before)[size_t(c)] == now[size_t(c)]);
            channels.push_back({{"name", name}, {"changed", changed}});
        }
        entry["channels"] = channels;
    };
    if (const auto* f3 = std::get_if<Field3DPtr>(&v); f3 && *f3) {
        const Box3d b = (*f3)->bounds();
        describe(**f3, {b.min[0], b.min[1], b.min[2]}, {b.max[0], b.max[1], b.max[2]});
    } else if (const auto* f2 = std::get_if<Field2DPtr>(&v); f2 && *f2) {
        const Box2d b = (*f2)->bounds();
        describe(**f2, {b.min[0], b.min[1]}, {b.max[0], b.max[1]});
    }
}

} // namespace

// `atlas cook GRAPH --frames A:B`: the graph's time sequence (its `time:` block),
// frame f into OUT/frame_NNNN/ with the keyed parameters at time start + f / fps.
// One session cooks them all, so a frame re-cooks only the nodes that read a
// keyed parameter and what depends on them. OUT/frames.json lists the frames,
// their times, folders and the nodes each cooked; it is written last, so a
// sequence that failed half way has none.
int run_cook_frames(const Args& a, CookOptions o) {
    if (a.positional.size() != 1) throw UsageError{"--frames cooks one graph's time sequence; give one graph", "cook"};
    const bool quiet = a.has("--quiet");
    Session session(builtin_nodes());
    session.load(a.positional[0]);
    apply_sets(session, a, "cook");
    const Graph& g = session.graph();
    if (!g.time)
        throw UsageError{"--frames: " + a.positional[0] + " declares no time range (add time: {start: 0, end: 300, fps: 1}; docs/graph-format.md, \"Time\")",
                         "cook"};
    const int total = g.time->frames();
    int first = 0, last = total - 1;
    const std::string spec = a.get("--frames");
    if (spec != "all") {
        const auto colon = spec.find(':');
        try {
            size_t used = 0;
            first = std::stoi(spec.substr(0, colon), &used);
            if (used != (colon == std::string::npos ? spec.size() : colon)) throw std::invalid_argument("x");
            last = first;
            if (colon != std::string::npos) {
                last = std::stoi(spec.substr(colon + 1), &used);
                if (used != spec.size() - colon - 1) throw std::invalid_argument("x");
            }
        } catch (const std::exception&) {
            throw UsageError{"--frames expects A:B (frame numbers, inclusive), N or all, got '" + spec + "'", "cook"};
        }
        if (first < 0 || last < first || last >= total)
            throw UsageError{"--frames " + spec + ": the graph's frames are 0:" + std::to_string(total - 1) + " (" + std::to_string(total) + " frames at " +
                                 format_param_value(g.time->fps) + " fps from " + format_param_value(g.time->start) + " s)",
                             "cook"};
    }
    if (!a.all("--output").empty()) o.outputs = a.all("--output");
    // Inputs another graph writes (requires:) are cooked once, before the frames.
    session.cook_requirements(o, [&](const GraphRequirement& r) {
        if (!quiet) std::cerr << "atlas: " << a.positional[0] << " reads files " << r.graph.string() << " writes: cooking it into " << r.out.string() << " first\n";
    });
    const std::filesystem::path out = o.out_dir;
    const int digits = std::max(4, int(std::to_string(total - 1).size()));
    ProgressBar bar(!quiet);
    nlohmann::json manifest = {{"graph", a.positional[0]},
                               {"time", {{"start", g.time->start}, {"end", g.time->end}, {"fps", g.time->fps}, {"frames", total}}},
                               {"frames", nlohmann::json::array()}};
    std::vector<std::pair<std::string, CookResult>> cooks;
    std::map<std::string, std::string> last_hashes; // output file -> its files' content hashes in the frame before
    // node.port -> its value's channel hashes, in the frame before and in this one
    // (outputs of one value, an EXR and a PNG of the same set, hash it once).
    std::map<std::string, std::vector<Hash128>> last_channels, channels_now;
    std::set<std::string> changing;                 // outputs whose bytes changed after the first frame
    for (int f = first; f <= last; ++f) {
        bar.begin_part(f - first, last - first + 1);
        const double t = g.time->at_frame(f);
        session.set_time(t);
        std::string number = std::to_string(f);
        const std::string folder = "frame_" + std::string(size_t(std::max(0, digits - int(number.size()))), '0') + number;
        CookOptions fo = o;
        fo.out_dir = out / folder;
        fo.progress = bar.sink();
        CookResult r;
        try {
            r = session.cook(fo);
        } catch (const std::exception&) {
            bar.finish();
            if (a.has("--report")) {
                cooks.emplace_back(a.positional[0] + "@" + folder, session.last_result());
                write_text_atomic(a.get("--report"), combined_report_json(cooks), "the report", {});
            }
            std::cerr << "atlas: frame " << f << " (t = " << format_param_value(t) << " s) failed; frames " << first << ".." << f - 1
                      << " were written, " << (out / "frames.json").string() << " was not\n";
            throw;
        }
        // Per output: its files and whether their bytes differ from the frame before
        // (a streaming engine reloads only what changed; frame_NNNN holds every file,
        // so a frame loads without reading another).
        nlohmann::json files = nlohmann::json::array(), outputs = nlohmann::json::array();
        // The outputs' values, the session's, in memory (one lookup for all).
        std::vector<std::pair<std::string, std::string>> ports;
        for (const auto& o2 : r.outputs) ports.emplace_back(o2.node, o2.port);
        const std::vector<Value> values = session.get(ports, fo);
        for (size_t k = 0; k < r.outputs.size(); ++k) {
            const auto& o2 = r.outputs[k];
            nlohmann::json of = nlohmann::json::array();
            std::string hashes;
            for (const auto& file : o2.files) {
                const std::string rel = std::filesystem::path(file.path).lexically_relative(out).generic_string();
                files.push_back(rel);
                of.push_back({{"path", rel}, {"bytes", file.bytes}, {"hash", file.hash}});
                hashes += file.hash + ";";
            }
            const auto prev = last_hashes.find(o2.file);
            const bool changed = f == first || prev == last_hashes.end() || prev->second != hashes;
            if (changed && f != first) changing.insert(o2.file);
            nlohmann::json entry = {{"file", o2.file}, {"node", o2.node}, {"format", o2.format}, {"changed", changed}, {"files", of}};
            // A field's world bounds and which of its channels differ from the frame
            // before (all of them in the first frame): what a streaming engine places
            // and re-uploads.
            std::vector<std::string> wanted;
            for (const GraphOutput& go : g.outputs)
                if (go.file == o2.file) wanted = io::OptionReader(go.options, go.file).list("channels");
            const Value& value = values[k];
            const std::string key = o2.node + "." + o2.port;
            if (!channels_now.count(key)) channels_now[key] = channel_hashes(value);
            const auto before = last_channels.find(key);
            describe_field_value(value, wanted, channels_now[key], before == last_channels.end() ? nullptr : &before->second, entry);
            outputs.push_back(std::move(entry));
            last_hashes[o2.file] = hashes;
        }
        manifest["frames"].push_back(
            {{"frame", f}, {"time", t}, {"folder", folder}, {"cooked", r.with_status("cooked")}, {"files", files}, {"outputs", outputs}});
        last_channels = std::move(channels_now);
        channels_now.clear();
        if (!quiet)
            std::fprintf(stderr, "frame %d (t = %s s): cooked %zu, cached %zu nodes\n", f, format_param_value(t).c_str(), r.with_status("cooked").size(),
                         r.with_status("cached").size());
        cooks.emplace_back(a.positional[0] + "@" + folder, std::move(r));
    }
    bar.finish();
    // Each output the frames wrote, once: its format and options (a DDS's
    // encoding) and whether any frame after the first changed it.
    nlohmann::json outs = nlohmann::json::array();
    for (const GraphOutput& go : g.outputs)
        if (last_hashes.count(go.file))
            outs.push_back({{"file", go.file}, {"node", go.node}, {"port", go.port}, {"format", go.format}, {"options", go.options},
                            {"changes", changing.count(go.file) > 0}});
    manifest["outputs"] = outs;
    write_text_atomic((out / "frames.json").string(), manifest.dump(2) + "\n", "the frame manifest", {});
    if (a.has("--report")) write_text_atomic(a.get("--report"), combined_report_json(cooks), "the report", {});
    if (!quiet) std::cout << (out / "frames.json").string() << "\n";
    return 0;
}

int run_cook(const Args& a) {
    if (a.positional.empty()) throw UsageError{"expected a graph file (or several)", "cook"};
    const bool quiet = a.has("--quiet");

    CookOptions o;
    o.out_dir = a.get("--out", ".");
    o.checked = a.has("--checked");
    o.allow_outside_out = a.has("--allow-outside-out");
    o.reuse_outputs = !a.has("--rewrite");
    o.keep_going = a.has("--keep-going");
    if (a.has("--jobs")) {
        try {
            o.jobs = std::stoi(a.get("--jobs"));
        } catch (...) {
            o.jobs = -1;
        }
        if (o.jobs < 1 || o.jobs > 1024) throw UsageError{"--jobs expects a number of threads >= 1, got '" + a.get("--jobs") + "'", "cook"};
    }
    if (a.has("--memory-budget")) o.memory_budget = parse_byte_size(a.get("--memory-budget"));
    o.cache_dir = cache_dir_flag(a, "cook");
    if (a.has("--cache-max-size")) {
        if (!o.cache_dir) throw UsageError{"--cache-max-size needs a cache (--cache DIR or ATLAS_CACHE_DIR)", "cook"};
        o.cache_max_bytes = parse_byte_size(a.get("--cache-max-size"));
    }

    if (a.has("--tiles") || a.has("--tile") || a.has("--assemble") || a.has("--no-tile-values")) {
        if (a.has("--frames")) throw UsageError{"--frames and --tiles: cook a sequence's frames one at a time", "cook"};
        return run_cook_tiled(a, o);
    }
    if (a.has("--frames")) return run_cook_frames(a, o);
    o.keep_values = false; // one cook per session: a value is freed once what reads it is done
    if (a.has("--report") && a.has("--depfile") && std::filesystem::path(a.get("--report")).lexically_normal() == std::filesystem::path(a.get("--depfile")).lexically_normal())
        throw UsageError{"--report and --depfile name one file", "cook"};
    const std::vector<ProtectedFile> graphs = cook_files(a, {});
    check_side_file(a, "--report", graphs);
    check_side_file(a, "--depfile", graphs);

    // Every graph cooks in its own session (one graph's nodes never see
    // another's) with the same options, so they share the disk cache.
    std::vector<std::pair<std::string, CookResult>> cooks;
    std::vector<std::string> requested = a.all("--output");
    std::set<std::string> matched, sets_matched;
    std::string failure;
    bool cancelled = false;
    ProgressBar bar(!quiet);
    for (const std::string& file : a.positional) {
        bar.begin_part(int(&file - a.positional.data()), int(a.positional.size()));
        Session session(builtin_nodes());
        try {
            session.load(file);
            apply_sets(session, a, "cook", a.positional.size() > 1 ? &sets_matched : nullptr);
            CookOptions go = o;
            go.progress = bar.sink();
            // --output names apply to the graphs that have them.
            for (const auto& name : requested)
                for (const auto& out : session.graph().outputs)
                    if (out.file == name || out.node == name) {
                        if (std::find(go.outputs.begin(), go.outputs.end(), name) == go.outputs.end()) go.outputs.push_back(name);
                        matched.insert(name);
                    }
            if (a.positional.size() == 1) go.outputs = requested; // one graph: unknown names are its error
            else if (!requested.empty() && go.outputs.empty()) {
                cooks.emplace_back(file, CookResult{});
                cooks.back().second.status = "ok";
                continue; // nothing requested from this graph
            }
            // Inputs another graph writes (the graph's requires:): cooked first when missing.
            for (auto& rc : session.cook_requirements(go, [&](const GraphRequirement& r) {
                     if (!quiet)
                         std::cerr << "atlas: " << file << " reads files " << r.graph.string() << " writes: cooking it into " << r.out.string()
                                   << " first\n";
                 }))
                cooks.push_back(std::move(rc));
            cooks.emplace_back(file, session.cook(go));
        } catch (const UsageError&) {
            throw;
        } catch (const std::exception& e) {
            CookResult r = session.last_result();
            r.status = dynamic_cast<const CancelledError*>(&e) ? "cancelled" : "failed";
            r.error = e.what();
            if (auto pe = dynamic_cast<const ParseError*>(&e)) r.error_where = pe->where().str();
            cooks.emplace_back(file, r);
            cancelled = r.status == "cancelled";
            failure = e.what();
            break; // a failed graph stops the call, as one failed graph stops a build
        }
    }
    bar.finish();
    if (failure.empty() && a.positional.size() > 1)
        for (const auto& name : requested)
            if (!matched.count(name)) failure = "unknown output '" + name + "': none of the graphs writes it";
    if (failure.empty() && a.positional.size() > 1)
        for (const auto& kv : a.all("--set"))
            if (!sets_matched.count(kv)) failure = "--set " + kv + ": none of the graphs has that node";

    if (a.has("--report")) {
        const std::string json = cooks.size() == 1 && a.positional.size() == 1 ? cooks[0].second.to_json(cooks[0].first) : combined_report_json(cooks);
        write_text_atomic(a.get("--report"), json, "the report", cook_files(a, cooks));
    }
    if (cancelled) throw CancelledError();
    if (!failure.empty()) throw Error(failure);

    if (a.has("--depfile")) {
        // TARGETS: DEPENDENCIES, in Make syntax (Ninja reads it as well).
        std::string targets, deps;
        std::set<std::string> seen_t, seen_d;
        for (const auto& [file, r] : cooks) {
            for (const auto& out : r.outputs)
                for (const auto& f : out.files)
                    if (seen_t.insert(f.path.string()).second) targets += (targets.empty() ? "" : " ") + depfile_escape(f.path.string());
            for (const auto& d : r.depends(file))
                if (seen_d.insert(d.string()).second) deps += " \\\n  " + depfile_escape(d.string());
        }
        auto protect = cook_files(a, cooks);
        if (a.has("--report")) protect.push_back({a.get("--report"), "the report"});
        write_text_atomic(a.get("--depfile"), targets + ":" + deps + "\n", "the depfile", protect);
    }

    size_t files = 0, current = 0;
    size_t cooked = 0, cached = 0, skipped = 0;
    double seconds = 0;
    std::vector<std::string> warnings;
    for (const auto& [file, r] : cooks) {
        for (const auto& out : r.outputs) {
            files += out.written.size();
            if (out.status == "up to date") current += out.files.size();
        }
        cooked += r.with_status("cooked").size();
        cached += r.with_status("cached").size();
        skipped += r.with_status("skipped").size();
        seconds += r.seconds;
        for (const auto& w : r.warnings) warnings.push_back(file + ": warning: " + w);
        for (const auto& [name, nr] : r.nodes)
            for (const auto& w : nr.warnings) warnings.push_back(file + ": warning: node '" + name + "': " + w);
    }
    // stdout: one summary line, then the written files (data for scripts).
    std::cout << "cooked " << cooked << ", cached " << cached << ", skipped " << skipped << " nodes in " << seconds << " s; wrote " << files
              << " files to " << o.out_dir.string() << "\n";
    for (const auto& [file, r] : cooks)
        for (const auto& out : r.outputs)
            for (const auto& p : out.written) std::cout << p.string() << "\n";
    if (!quiet && current) std::cerr << current << " file" << (current == 1 ? "" : "s") << " already up to date (not rewritten)\n";
    // GPU texture memory of the DDS outputs, per graph, against its budget (report.md "textures").
    for (const auto& [file, r] : cooks) {
        const uint64_t tex = r.texture_bytes();
        if (quiet || (!tex && !r.texture_budget_mb)) continue;
        std::ostringstream line;
        line.precision(3);
        line << file << ": textures " << double(tex) / 1e6 << " MB";
        if (r.texture_budget_mb) line << " of the " << *r.texture_budget_mb << " MB budget";
        std::cerr << line.str() << "\n";
    }
    // Warnings are not a summary: --quiet keeps them (a broken cache entry must be seen).
    for (const auto& w : warnings) std::cerr << w << "\n";
    return 0;
}

int run_validate(const Args& a) {
    const std::string file = one_graph(a, "validate");
    Session session(builtin_nodes());
    session.load(file);
    apply_sets(session, a, "validate");
    const Graph& g = session.graph();
    const auto missing = session.missing_inputs();
    for (const auto& m : missing)
        std::cerr << file << ":" << m.line << ": warning: node '" << m.node << "' (" << m.type << ") parameter '" << m.param << "': " << m.path.string()
                  << " does not exist: "
                  << (m.written_by ? "`atlas cook` will cook " + m.written_by->graph.string() + " into " + m.written_by->out.string() +
                                         " first (the graph's requires:)"
                                   : std::string("the cook will fail unless something writes it first"))
                  << "\n";
    std::cout << file << ": ok (" << g.nodes.size() << " nodes, " << g.outputs.size() << " outputs"
              << (missing.empty() ? std::string() : ", " + std::to_string(missing.size()) + " input file(s) missing") << ")\n";
    return 0;
}

} // namespace atlas::cli
