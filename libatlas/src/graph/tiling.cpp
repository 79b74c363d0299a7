// Tiled cooking (atlas/graph/tiling.h, docs/scale.md): the tiled cook's steps (regions per
// node, each tile cooked and written, the tile index, assembly) and the public entries; the
// parts they use (the plan, the grid's geometry and crops, file names, fragments, reports)
// are in tile_parts.h.
#include "atlas/core/progress.h"
#include "atlas/graph/tiling.h"
#include "cook_steps.h"
#include "graph_walk.h"
#include "tile_parts.h"

#include "atlas/compress/texture.h"
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/core/parallel.h"
#include "atlas/io/writers.h"
#include "output_records.h"
#include "value_cache.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <set>


namespace atlas {

namespace {

using namespace detail::tiles;
using detail::source_port;
using detail::topological_order;

// A tiled cook, step by step: select the tiles (those on disk and current are kept),
// cook the generators whole, check the grid, cook and write each tile, then the
// index and (optionally) the assembled outputs. It shares plan, resolve, a node's cook
// and the outputs' placing with the untiled cook (cook_steps.h).
struct TiledCook {
    TiledCook(Session& s, const CookOptions& o, const TileOptions& to, TiledCookResult& r);
    void select_tiles();
    void cook_sources();
    void check_grid();
    void cook_tiles();
    void write_index();
    void share_ranges();
    void assemble();

    using Staging = std::map<fs::path, std::unique_ptr<StagedOutputs>>;
    struct Untiled {
        const GraphOutput* out = nullptr;
        detail::OutputPlace place;
        std::string name;
        detail::OutputSpec spec;
    };
    Untiled untiled(const GraphOutput& o) const;
    OutputRecords& records_in(const fs::path& out_root);
    const OutputRecord* current(const Untiled& u);
    void record(const Untiled& u, const std::vector<fs::path>& finals);
    void save_records();
    std::map<fs::path, std::unique_ptr<OutputRecords>> records; // per output root (output_records.h)
    std::vector<std::pair<size_t, std::vector<fs::path>>> pending_whole;
    StagedOutputs& staged_in(Staging& staging, const fs::path& out_root) const;
    void commit_all(Staging& staging);
    std::string tile_key(Vec2i t) const;
    HeldValues cook_tile(const TileRect& tr, ThreadLimit& arena, uint64_t& value_peak);
    json write_tile(Vec2i t, const TileRect& tr, const HeldValues& held);
    Value read_raw(const json& fo, Vec2i t) const;

    const std::chrono::steady_clock::time_point t_start = std::chrono::steady_clock::now();
    Session& session;
    const CookOptions& opt;
    const TileOptions& topt;
    TiledCookResult& result;
    const Graph& g;
    const NodeRegistry& reg;
    const Vec2i tiles;
    Plan plan;
    const MemoryBudget budget;
    const fs::path root;
    std::map<std::string, Hash128> hashes;
    std::vector<Vec2i> selection, to_cook;
    std::map<std::pair<int, int>, json> fragments; // per tile, cooked now or found current
    HeldValues sources; // generators cooked whole
    HeldValues aside;   // values passed whole to every tile (Plan::aside)
    // The outputs on the tiled grid, and those written whole once (on another grid, or not fields).
    std::vector<const GraphOutput*> tiled_outputs, whole_outputs;
    Grid grid;
};

TiledCook::TiledCook(Session& s, const CookOptions& o, const TileOptions& to, TiledCookResult& r)
    : session(s), opt(o), topt(to), result(r), g(s.graph()), reg(s.registry()), tiles(to.tiles),
      plan((check_tile_counts(to), make_plan(g, reg, o.outputs))), budget(o.memory_budget), root(o.out_dir) {
    remove_stale_staging(root);
    result = TiledCookResult{};
    result.tiles = tiles;
    result.jobs = opt.jobs > 0 ? opt.jobs : hardware_threads();
    hashes = session.node_hashes();
}

std::string TiledCook::tile_key(Vec2i t) const {
    Hasher h;
    h.add("atlas-tile").add(int64_t(kTileFormatVersion)).add(int64_t(tiles[0])).add(int64_t(tiles[1])).add(int64_t(t[0])).add(int64_t(t[1]));
    if (!topt.exact_values) h.add("no exact values");
    for (const GraphOutput* o : plan.outputs) {
        h.add(hashes.at(o->node)).add(o->port).add(o->format).add(o->file).add(int64_t(io::output_formats().size()));
        for (const auto& f : io::output_formats())
            if (f.name == o->format) h.add(int64_t(f.version));
        for (const auto& [k, v] : o->options) h.add(k).add(v);
    }
    return h.finish().hex();
}

// The tiles asked for; those on disk and current (e.g. cooked by other workers) are kept.
// A folder holding another tiling's tiles is refused: their files share names (I_J) and
// would mix.
void TiledCook::select_tiles() {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(root / "tiles", ec)) {
        const std::string name = e.path().filename().string();
        if (e.path().extension() != ".json" || name == "index.json") continue;
        try {
            const json f = json::parse(read_file_bytes(e.path()));
            const Vec2i other{{f.at("tiles").at(0).get<int>(), f.at("tiles").at(1).get<int>()}};
            if (other != tiles)
                throw Error("'" + (root / "tiles").string() + "' holds the tiles of another tiled cook (" + name + ": --tiles " + tile_name(other) +
                            "); a cook with --tiles " + tile_name(tiles) + " would mix their files: use another --out, or remove that folder");
        } catch (const Error&) {
            throw;
        } catch (const std::exception&) {
            // Not a fragment (or a damaged one, cooked again): nothing to compare.
        }
    }
    if (topt.only) selection.push_back(*topt.only);
    else
        for (int j = 0; j < tiles[1]; ++j)
            for (int i = 0; i < tiles[0]; ++i) selection.push_back({{i, j}});

    for (Vec2i t : selection) {
        if (opt.reuse_outputs && !opt.checked)
            if (auto f = current_fragment(root, t, tile_key(t))) {
                fragments[{t[0], t[1]}] = std::move(*f);
                continue;
            }
        to_cook.push_back(t);
    }
}

// Generators: cooked whole (through the session's caches) and cropped per tile; they set the XY grid.
// A source some tiled node reads sets it before one only outputs read: such an output on another
// grid (a LUT, a baked volume of its own size, a table) is not tiled but written whole, once.
void TiledCook::cook_sources() {
    std::set<std::pair<std::string, std::string>> whole; // outputs written whole: node, port
    if (to_cook.empty()) {
        const json& f = fragments.begin()->second;
        grid = grid_from_json(f.at("grid"));
        for (const auto& w : f.value("whole_outputs", json::array())) whole.insert({w.at(0).get<std::string>(), w.at(1).get<std::string>()});
    } else {
        // The grids of the sources: a feeding source (one a tiled node reads) of the most texels
        // sets the tiled grid; chains that start on other grids and never meet it are cooked
        // whole (as outputs on a grid of their own are), a node that reads two grids is refused.
        struct Found {
            const GraphNode* n;
            std::string port; // empty for a windowed generator (cooked per tile)
            Value v;
            Grid at;
            bool feeding;
        };
        std::vector<Found> found;
        for (const bool feeding : {true, false})
            for (const GraphNode* n : plan.order) {
                if (!plan.sources.count(n->name) || (plan.tiled_reads.count(n->name) > 0) != feeding) continue;
                if (auto it = plan.windowed.find(n->name); it != plan.windowed.end()) {
                    const TileGrid& tg = it->second;
                    found.push_back({n, "", {}, {tg.res, tg.bounds.min, tg.bounds.max, n->name}, feeding});
                    continue;
                }
                std::set<std::string> ports;
                if (auto r = plan.tiled_reads.find(n->name); r != plan.tiled_reads.end()) ports = r->second;
                for (const GraphOutput* o : plan.outputs)
                    if (o->node == n->name) ports.insert(o->port);
                for (const std::string& port : ports) {
                    Value v = session.get(n->name, port, opt);
                    if (!is_field(v)) {
                        if (!feeding) {
                            whole.insert({n->name, port});
                            continue;
                        }
                        throw Error(node_label(*n) + ": output '" + port + "' is a " + std::string(port_type_name(value_type(v))) +
                                    ", which does not tile (only fields do)");
                    }
                    Grid at;
                    at.from = n->name;
                    field_xy(v, at.res, at.lo, at.hi);
                    found.push_back({n, port, std::move(v), at, feeding});
                }
            }
        auto same = [](const Grid& x, const Grid& y) { return x.res == y.res && x.lo == y.lo && x.hi == y.hi; };
        auto texels = [](const Grid& x) { return int64_t(x.res[0]) * int64_t(x.res[1]); };
        // Without feeding sources (outputs read the sources directly) the first one's grid.
        const bool any_feeding = std::any_of(found.begin(), found.end(), [](const Found& f) { return f.feeding; });
        for (const Found& f : found)
            if (any_feeding ? f.feeding && (grid.from.empty() || texels(f.at) > texels(grid)) : grid.from.empty()) grid = f.at;
        std::map<std::string, Grid> off; // nodes of chains on another grid: cooked whole
        for (Found& f : found) {
            if (same(f.at, grid)) {
                if (!f.port.empty()) sources[{f.n->name, f.port}] = {std::move(f.v), {0, 0, f.at.res[0], f.at.res[1]}, false};
                continue;
            }
            // Off the grid: cooked whole, not per tile. A port only outputs read is written whole
            // (a source's other ports may be on the grid); a windowed generator is off as a whole.
            if (f.feeding || f.port.empty()) off.emplace(f.n->name, f.at);
            else whole.insert({f.n->name, f.port});
        }
        std::vector<const GraphNode*> on;
        for (const GraphNode* n : plan.order) {
            if (off.count(n->name)) continue;
            const auto& whole_in = reg.find(n->type)->decl.tiling().whole_inputs;
            const Grid* other = nullptr;
            const GraphNode* from_on = nullptr;
            for (const auto& [port, b] : n->inputs) {
                if (whole_in.count(port)) continue;
                if (auto it = off.find(b.node); it != off.end()) other = &it->second;
                else from_on = g.find(b.node);
            }
            if (other && from_on)
                throw Error(node_label(*n) + ": it reads values on two XY grids, the " + xy_text(other->res) + " grid of node '" + other->from +
                            "' and the tiled " + xy_text(grid.res) + " grid of node '" + grid.from +
                            "' (tiling needs one grid per chain: cook the outputs of each grid in tiles separately, --output NAME)");
            if (other) off.emplace(n->name, *other);
            else on.push_back(n);
        }
        if (!off.empty()) {
            for (const GraphOutput* o : plan.outputs)
                if (off.count(o->node)) whole.insert({o->node, o->port});
            plan.order = std::move(on);
            for (const auto& [name, at] : off) plan.sources.erase(name), plan.windowed.erase(name);
        }
        if (grid.from.empty()) throw Error("tiling: no output of the graph is a field on a grid to tile");
        for (const auto& [node, port] : plan.aside) aside[{node, port}] = {session.get(node, port, opt), {}, true};
    }
    for (const GraphOutput* o : plan.outputs) (whole.count({o->node, o->port}) ? whole_outputs : tiled_outputs).push_back(o);
    if (tiled_outputs.empty()) throw Error("tiling: no output of the graph is on the tiled grid");
    result.grid = grid.res;
}

void TiledCook::check_grid() {
    // The tile count must divide the grid; BC-compressed outputs need 4x4-block-aligned tiles.
    for (int a = 0; a < 2; ++a)
        if (grid.res[a] % tiles[a] != 0)
            throw Error("--tiles " + tile_name(tiles) + ": the " + xy_text(grid.res) + " grid (of node '" + grid.from + "') does not divide into " +
                        std::to_string(tiles[a]) + " tiles along " + (a ? "y" : "x") + " (" + std::to_string(grid.res[a]) + " is not a multiple of " +
                        std::to_string(tiles[a]) + ")");
    const Vec2i tile_size{{grid.res[0] / tiles[0], grid.res[1] / tiles[1]}};
    // Halos in world units (e.g. a clipped SDF's max_distance) become texels of this grid.
    for (const std::string& name : plan.grid_halo) {
        const GraphNode& n = *g.find(name);
        const NodeType* t = reg.find(n.type);
        NodeParams params(&t->decl, resolved_params(n, *t), g.base_dir);
        const int h = t->decl.tiling().grid_halo(params, TileGrid{grid.res, {grid.lo, grid.hi}});
        if (h < 0) throw Error(node_label(n) + ": internal: negative tiling halo");
        plan.halo[name] = h;
    }
    // A halo wider than a tile is exact but not cheaper per tile: said, not refused (the shipped
    // graphs clip their SDFs where the untiled bytes stay the same, which is often wider).
    for (const GraphNode* n : plan.order)
        if (const int h = plan.halo.at(n->name); h > std::min(tile_size[0], tile_size[1]))
            result.warnings.push_back(node_label(*n) + ": its tiling halo of " + std::to_string(h) + " texels is wider than a tile (" +
                                      xy_text(tile_size) + "): each tile cooks it over up to " + std::to_string(2 * h) +
                                      " texels more per axis, exact but not cheaper per tile" +
                                      (n->type == "volume/sdf" ? " (a nearer max_distance clips the halo)" : ""));
    for (const GraphOutput* o : tiled_outputs) {
        if (o->format == "dds" && (tile_size[0] % 4 || tile_size[1] % 4))
            throw Error(o->where.str() + ": --tiles " + tile_name(tiles) + ": output '" + o->file +
                        "' is BC-compressed in 4x4 blocks, and tiles of " + xy_text(tile_size) + " texels are not block-aligned");
        // Its tiles share the world's range from their exact values at the index step (share_ranges).
        if (!topt.exact_values && io::output_maps_by_own_range(o->format, o->options))
            throw Error(o->where.str() + ": output '" + o->file + "' maps its values by their own range (a DDS without option 'range'), so each tile " +
                        "must be re-encoded with the world's range once every tile is cooked, from the tile's exact values; " +
                        "--no-tile-values leaves none: set 'range: LO,HI' on the output, or keep the tile values");
    }
}

void TiledCook::cook_tiles() {
    ThreadLimit arena(opt.jobs);
    const int total_tiles = int(selection.size());
    int tiles_finished = int(selection.size() - to_cook.size());

    for (Vec2i t : to_cook) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::string tname = "tile " + tile_name(t);
        opt.progress.poll();
        if (opt.progress.on_progress) opt.progress.on_progress({tname, double(tiles_finished) / total_tiles, tiles_finished, total_tiles});
        const TileRect tr = tile_rect(grid.res, tiles, t);
        const double cpu0 = process_cpu_seconds();
        uint64_t value_peak = 0;
        try {
            const auto held = cook_tile(tr, arena, value_peak);
            fragments[{t[0], t[1]}] = write_tile(t, tr, held);
        } catch (const std::exception& e) {
            TileReport failed = tile_report(t, tr, dynamic_cast<const CancelledError*>(&e) ? "cancelled" : "failed", seconds_since(t0),
                                            process_cpu_seconds() - cpu0, value_peak, nullptr, root);
            failed.error = e.what();
            result.tiles_done.push_back(std::move(failed));
            result.seconds = seconds_since(t_start);
            if (dynamic_cast<const CancelledError*>(&e)) throw;
            const std::string msg = e.what();
            if (dynamic_cast<const MemoryBudgetError*>(&e)) throw MemoryBudgetError(tname + ": " + msg);
            throw Error(tname + ": " + msg);
        }
        result.tiles_done.push_back(
            tile_report(t, tr, "cooked", seconds_since(t0), process_cpu_seconds() - cpu0, value_peak, &fragments.at({t[0], t[1]}), root));
        ++tiles_finished;
        if (opt.progress.on_progress) opt.progress.on_progress({tname, double(tiles_finished) / total_tiles, tiles_finished, total_tiles});
    }
    for (Vec2i t : selection)
        if (std::none_of(to_cook.begin(), to_cook.end(), [&](Vec2i c) { return c == t; }))
            result.tiles_done.push_back(tile_report(t, tile_rect(grid.res, tiles, t), "up to date", 0, 0, 0, &fragments.at({t[0], t[1]}), root));
}

// A tile's values: every node on its region, the tile grown by the halos of the nodes downstream.
HeldValues TiledCook::cook_tile(const TileRect& tr, ThreadLimit& arena, uint64_t& value_peak) {
    // Regions: outputs need the tile; a node needs its region grown by its halo from each input.
    std::map<std::string, TileRect> region;
    for (const GraphOutput* o : tiled_outputs) region[o->node] = unite(region[o->node], tr);
    for (auto it = plan.order.rbegin(); it != plan.order.rend(); ++it) {
        const GraphNode& n = **it;
        const TileRect need = grow(region[n.name], plan.halo.at(n.name), grid.res);
        const auto& whole = reg.find(n.type)->decl.tiling().whole_inputs;
        for (const auto& [port, b] : n.inputs)
            if (!whole.count(port)) region[b.node] = unite(region[b.node], need);
    }
    HeldValues held;
    for (const GraphNode* n : plan.order) {
        const TileRect r = region.at(n->name);
        const bool windowed = plan.windowed.count(n->name) > 0;
        if (plan.sources.count(n->name) && !windowed) {
            for (const auto& [key, h] : sources)
                if (key.first == n->name) held[key] = {crop(h.v, h.rect, r, grid, budget), r, false};
            continue;
        }
        const NodeType& type = *reg.find(n->type);
        const TileRect in_rect = windowed ? r : grow(r, plan.halo.at(n->name), grid.res);
        const TileWindow window = window_of(grid, r);
        std::map<std::string, Value> inputs;
        for (const auto& [port, b] : n->inputs) {
            if (type.decl.tiling().whole_inputs.count(port)) {
                inputs[port] = aside.at({b.node, source_port(g, reg, b)}).v;
                continue;
            }
            const Held& h = held.at({b.node, source_port(g, reg, b)});
            inputs[port] = h.whole ? h.v : crop(h.v, h.rect, in_rect, grid, budget);
        }
        NodeParams params(&type.decl, resolved_params(*n, type), g.base_dir);
        ProgressSink node_progress;
        node_progress.is_cancelled = opt.progress.is_cancelled;
        const TileWindow in_window = window_of(grid, in_rect);
        const TileWindow* node_window = windowed ? &window : plan.reads_window.count(n->name) ? &in_window : nullptr;
        {
            // Memory: what is held for later nodes, this node's inputs and (below) its outputs.
            std::vector<Value> alive;
            for (const auto& [key, h] : held) alive.push_back(h.v);
            for (const auto& [port, v] : inputs) alive.push_back(v);
            value_peak = std::max(value_peak, distinct_bytes(alive));
        }
        detail::NodeRun run;
        try {
            arena.run([&] { run = detail::cook_node(*n, type, params, std::move(inputs), budget, node_progress, node_window); });
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            std::string msg = e.what();
            // CookContext::fail already names the node: name it once, with its place.
            const std::string own = "node '" + n->name + "' (" + n->type + "): ";
            if (msg.rfind(own, 0) == 0) msg.erase(0, own.size());
            throw Error(node_label(*n) + ": " + msg);
        }
        {
            std::vector<Value> alive;
            for (const auto& [key, h] : held) alive.push_back(h.v);
            for (const auto& [port, v] : run.outputs) alive.push_back(v);
            value_peak = std::max(value_peak, distinct_bytes(alive));
        }
        const Box2d want = rect_bounds(grid, in_rect);
        for (const auto& out : type.decl.outputs()) {
            auto it = run.outputs.find(out.name);
            if (!is_field(it->second)) {
                throw Error(node_label(*n) + ": output '" + out.name + "' is not a field, so it does not tile");
            }
            Vec2i res;
            Vec2d lo, hi;
            field_xy(it->second, res, lo, hi);
            if (res != Vec2i{{in_rect.width(), in_rect.height()}} || lo != want.min || hi != want.max)
                throw Error(node_label(*n) + ": its output '" + out.name + "' is not on the grid of its inputs (" + xy_text(res) +
                            " texels for a " + xy_text({{in_rect.width(), in_rect.height()}}) +
                            " region), so it cannot be cooked in tiles");
            held[{n->name, out.name}] = {crop(it->second, in_rect, r, grid, budget), r, false};
        }
        // Memory: drop what no later node and no output reads.
        for (const auto& [port, b] : n->inputs)
            if (plan.last_use.at(b.node) == n->name && !plan.output_nodes.count(b.node))
                for (auto h = held.begin(); h != held.end();) h = h->first.first == b.node ? held.erase(h) : std::next(h);
    }
    return held;
}

// A tile's files: every output in its format, the exact values, and the fragment that
// records them (it lands after the files it names).
json TiledCook::write_tile(Vec2i t, const TileRect& tr, const HeldValues& held) {
    StagedOutputs st(root);
    if (!g.file.empty()) st.protect({{g.file, "the graph file"}});
    json frag = {{"atlas_tile", kTileFormatVersion}, {"key", tile_key(t)}, {"tile", {t[0], t[1]}},
                 {"tiles", {tiles[0], tiles[1]}}, {"texels", {tr.x0, tr.y0, tr.x1, tr.y1}}, {"grid", grid_json(grid)},
                 {"outputs", json::array()}, {"whole_outputs", json::array()}, {"made_by", made_by()}};
    for (const GraphOutput* o : whole_outputs) frag["whole_outputs"].push_back({o->node, o->port});
    const Box2d tb = rect_bounds(grid, tr);
    for (const GraphOutput* o : tiled_outputs) {
        const Held& h = held.at({o->node, o->port});
        const Value v = crop(h.v, h.rect, tr, grid, budget);
        io::OutputMetrics metrics;
        std::vector<fs::path> staged;
        try {
            staged = io::write_value(v, st.stage(tile_rel(*o, t)), o->format, o->options, &metrics);
        } catch (const std::exception& e) {
            throw Error(detail::output_error(*o, e.what()));
        }
        json files = json::array();
        for (const auto& s : staged) files.push_back(file_entry(root, st.final_path(s), s));
        json entry = {{"file", o->file}, {"node", o->node}, {"port", o->port}, {"format", o->format},
                      {"bounds_min", {tb.min[0], tb.min[1]}}, {"bounds_max", {tb.max[0], tb.max[1]}}, {"files", files}};
        // Quantised by its own range: recorded, so that the index step can give every tile the world's.
        if (const auto own = io::output_own_range(v, o->format, o->options)) {
            entry["own_range"] = range_json(*own);
            entry["range"] = range_json(compress::mapped_value_range(*own));
        }
        if (topt.exact_values) {
            // The exact values, once per node port (several outputs may write one).
            const fs::path raw_rel = fs::path("tiles") / "values" / (o->node + "." + o->port + "." + std::to_string(t[0]) + "_" + std::to_string(t[1]) + ".atlastile");
            const fs::path raw = st.stage(raw_rel);
            if (!fs::exists(raw)) {
                const std::string bytes = disk_cache::serialize({{"value", v}});
                write_file_checked(raw, bytes.data(), bytes.size());
            }
            entry["raw"] = file_entry(root, st.final_path(raw), raw);
        }
        frag["outputs"].push_back(std::move(entry));
    }
    const std::string text = frag.dump(2) + "\n";
    // The fragment is the tile's record: it lands after the files it names.
    write_file_checked(st.stage_last(fragment_rel(t)), text.data(), text.size());
    for (const auto& p : st.commit()) result.written.push_back(p);
    return frag;
}

// A tile's exact values of one output (its fragment entry `fo`), checked against the hash
// the tile recorded.
Value TiledCook::read_raw(const json& fo, Vec2i t) const {
    const fs::path raw = root / fo.at("raw").at("path").get<std::string>();
    std::string why;
    const std::string bytes = read_file_bytes(raw);
    if (ContentHasher().add(bytes.data(), bytes.size()).finish().hex() != fo.at("raw").at("hash").get<std::string>())
        throw Error("tile " + tile_name(t) + ": '" + raw.string() + "' changed after the tile was cooked (another cook writes into this folder?)");
    auto vals = disk_cache::deserialize(bytes, &why);
    if (!vals || !vals->count("value")) throw Error("tile " + tile_name(t) + ": '" + raw.string() + "' is unreadable (" + why + ")");
    return vals->at("value");
}

// Outputs quantised by their own range (a DDS without 'range'): each tile was encoded with
// its own, so neighbours quantise differently at their border. With every tile cooked, the
// world's range is the union of theirs (the range the untiled texture maps from); each tile
// encoded with another is encoded again from its exact values with the world's, and its
// fragment rewritten. A second cook finds every tile on the world's range: nothing to do.
void TiledCook::share_ranges() {
    for (size_t k = 0; k < tiled_outputs.size(); ++k) {
        const GraphOutput* o = tiled_outputs[k];
        std::optional<std::pair<float, float>> own;
        for (const auto& [t, f] : fragments) {
            const auto r = range_of(f.at("outputs").at(k).value("own_range", json()));
            if (!r) continue;
            own = own ? std::make_pair(std::min(own->first, r->first), std::max(own->second, r->second)) : *r;
        }
        if (!own && !std::any_of(fragments.begin(), fragments.end(), [&](const auto& f) { return f.second.at("outputs").at(k).contains("range"); }))
            continue; // not quantised by its own range
        const std::pair<float, float> world = compress::mapped_value_range(own.value_or(std::make_pair(INFINITY, -INFINITY)));
        const io::OutputOptions options = io::with_range(o->options, world);
        for (auto& [t, f] : fragments) {
            json& fo = f.at("outputs").at(k);
            if (range_of(fo.at("range")) == std::optional(world)) continue;
            opt.progress.poll();
            const Vec2i tile{{t.first, t.second}};
            StagedOutputs st(root);
            if (!g.file.empty()) st.protect({{g.file, "the graph file"}});
            json files = json::array();
            try {
                for (const auto& p : io::write_value(read_raw(fo, tile), st.stage(tile_rel(*o, tile)), o->format, options, nullptr))
                    files.push_back(file_entry(root, st.final_path(p), p));
            } catch (const CancelledError&) {
                throw;
            } catch (const std::exception& e) {
                throw Error("tile " + tile_name(tile) + ": " + detail::output_error(*o, std::string("with the world's range: ") + e.what()));
            }
            fo["files"] = files;
            fo["range"] = range_json(world);
            const std::string text = f.dump(2) + "\n";
            write_file_checked(st.stage_last(fragment_rel(tile)), text.data(), text.size());
            for (const auto& p : st.commit()) result.written.push_back(p);
            // The report lists the tile's files as they now are.
            for (TileReport& r : result.tiles_done)
                if (r.tile == tile) r.files = tile_report(tile, r.texels, r.status, 0, 0, 0, &f, root).files;
        }
    }
}

// Every tile is present: the tile index.
void TiledCook::write_index() {
    // Every tile as this cook knows it is still what is on disk: another cook writing into
    // the folder (another graph, or an edit of this one) would otherwise leave an index that
    // mixes two runs' tiles.
    for (int j = 0; j < tiles[1]; ++j)
        for (int i = 0; i < tiles[0]; ++i)
            if (!current_fragment(root, {{i, j}}, tile_key({{i, j}})))
                throw Error("tile " + tile_name({{i, j}}) + " changed on disk after this cook wrote or checked it (another cook writes into '" +
                            root.string() + "'?): no index written and nothing assembled; cook again, or give each run its own --out");
    share_ranges();
    json index = {{"atlas_tile_index", kTileFormatVersion}, {"graph", topt.graph_name}, {"tiles", {tiles[0], tiles[1]}},
                  {"grid", grid_json(grid)}, {"outputs", json::array()}};
    for (size_t k = 0; k < tiled_outputs.size(); ++k) {
        const GraphOutput* o = tiled_outputs[k];
        json entry = {{"file", o->file}, {"node", o->node}, {"port", o->port}, {"format", o->format}, {"options", o->options}, {"tiles", json::array()}};
        if (const json& r = fragments.begin()->second.at("outputs").at(k); r.contains("range")) entry["range"] = r.at("range"); // every tile's
        for (int j = 0; j < tiles[1]; ++j)
            for (int i = 0; i < tiles[0]; ++i) {
                const json& f = fragments.at({i, j});
                const json& fo = f.at("outputs").at(k);
                json tile = {{"tile", {i, j}}, {"texels", f.at("texels")}, {"bounds_min", fo.at("bounds_min")},
                             {"bounds_max", fo.at("bounds_max")}, {"files", fo.at("files")}, {"made_by", f.value("made_by", json::object())}};
                if (fo.contains("raw")) tile["raw"] = fo.at("raw");
                entry["tiles"].push_back(std::move(tile));
            }
        index["outputs"].push_back(entry);
    }
    // Outputs not on the tiled grid, written whole as an untiled cook writes them
    // (unless their files from an earlier cook are current).
    Staging staging;
    std::vector<std::pair<Untiled, std::vector<fs::path>>> written;
    for (const GraphOutput* o : whole_outputs) {
        Untiled u = untiled(*o);
        std::vector<fs::path> finals;
        if (const OutputRecord* r = current(u)) {
            for (const auto& f : r->files) finals.push_back(u.place.root / f.path);
        } else {
            const Value v = session.get(o->node, o->port, opt);
            StagedOutputs& st = staged_in(staging, u.place.root);
            try {
                for (const auto& f : io::write_value(v, st.stage(u.place.rel), o->format, o->options, nullptr)) finals.push_back(st.final_path(f));
            } catch (const std::exception& e) {
                throw Error(detail::output_error(*o, e.what()));
            }
            written.push_back({u, finals});
        }
        index["outputs"].push_back({{"file", o->file}, {"node", o->node}, {"port", o->port}, {"format", o->format}, {"options", o->options},
                                    {"whole", true}, {"files", json::array()}});
        pending_whole.push_back({index["outputs"].size() - 1, finals});
    }
    commit_all(staging);
    for (auto& [u, finals] : written) record(u, finals);
    for (const auto& [k, finals] : pending_whole)
        for (const auto& f : finals) index["outputs"][k]["files"].push_back(file_entry(root, f, f));
    pending_whole.clear();
    save_records();
    // The index: written when it changed (a second identical cook writes nothing).
    const fs::path p = root / "tiles" / "index.json";
    const std::string text = index.dump(2) + "\n";
    result.index = p;
    std::error_code ec;
    if (fs::file_size(p, ec) == text.size() && !ec && read_file_bytes(p) == text) return;
    write_file_atomic(p, [&](const fs::path& tmp) { write_file_checked(tmp, text.data(), text.size()); });
    result.written.push_back(p);
}

// An output this cook writes untiled (assembled, or whole): where it lands and its
// key, as the untiled cook computes them, so either cook finds the other's files current.
TiledCook::Untiled TiledCook::untiled(const GraphOutput& o) const {
    Untiled u;
    u.out = &o;
    u.place = detail::output_place(root, o, opt.allow_outside_out);
    u.name = u.place.rel.generic_string();
    u.spec = detail::output_spec(o, u.name, hashes.at(o.node));
    return u;
}

OutputRecords& TiledCook::records_in(const fs::path& out_root) {
    auto& rec = records[out_root];
    if (!rec) rec = std::make_unique<OutputRecords>(out_root);
    return *rec;
}

const OutputRecord* TiledCook::current(const Untiled& u) {
    if (!opt.reuse_outputs || opt.checked) return nullptr;
    return records_in(u.place.root).current(u.name, u.spec.key.hex());
}

void TiledCook::record(const Untiled& u, const std::vector<fs::path>& finals) {
    OutputRecord rec;
    rec.key = u.spec.key.hex();
    rec.spec = u.spec.spec;
    for (const auto& f : finals)
        rec.files.push_back({f.lexically_relative(u.place.root).generic_string(), uint64_t(fs::file_size(f)), file_mtime_ns(f), file_content_hash(f).hex()});
    records_in(u.place.root).set(u.name, std::move(rec));
}

void TiledCook::save_records() {
    for (auto& [r, rec] : records)
        if (rec->changed()) rec->save();
}

// The staging of the folder an output lands in (an output may be placed outside --out).
StagedOutputs& TiledCook::staged_in(Staging& staging, const fs::path& out_root) const {
    auto& st = staging[out_root];
    if (!st) {
        st = std::make_unique<StagedOutputs>(out_root);
        if (!g.file.empty()) st->protect({{g.file, "the graph file"}});
    }
    return *st;
}

void TiledCook::commit_all(Staging& staging) {
    for (auto& [r, st] : staging) st->prepare(); // every root checked before any file moves
    for (auto& [r, st] : staging)
        for (const auto& p : st->commit()) result.written.push_back(p);
}

// The untiled outputs, from the tiles' exact values.
void TiledCook::assemble() {
    Staging staging;
    std::vector<std::pair<Untiled, std::vector<fs::path>>> written;
    for (size_t k = 0; k < tiled_outputs.size(); ++k) {
        const GraphOutput* o = tiled_outputs[k];
        const Untiled u = untiled(*o);
        if (current(u)) continue; // its files from an earlier cook (tiled or not) hold these bytes
        if (opt.progress.on_progress) opt.progress.on_progress({"assembling " + o->file, 1.0, int(selection.size()), int(selection.size())});
        try {
            std::shared_ptr<Field2D> full2;
            std::shared_ptr<Field3D> full3;
            for (int j = 0; j < tiles[1]; ++j)
                for (int i = 0; i < tiles[0]; ++i) {
                    const json& fo = fragments.at({i, j}).at("outputs").at(k);
                    const fs::path raw = root / fo.at("raw").at("path").get<std::string>();
                    const Value v = read_raw(fo, {{i, j}});
                    const TileRect r = tile_rect(grid.res, tiles, {{i, j}});
                    const Box2d gb = rect_bounds(grid, {0, 0, grid.res[0], grid.res[1]});
                    if (auto t2 = std::get_if<Field2DPtr>(&v)) {
                        const Field2D& f = **t2;
                        if (f.resolution() != Vec2i{{r.width(), r.height()}}) throw Error("tile " + tile_name({{i, j}}) + ": '" + raw.string() + "' has the wrong size");
                        if (full3) throw Error("tile " + tile_name({{i, j}}) + ": a 2D tile among 3D ones");
                        if (!full2) full2 = std::make_shared<Field2D>(grid.res, f.channels(), gb, f.channel_names(), &budget);
                        Field2D& dst = *full2;
                        if (dst.channels() != f.channels()) throw Error("tile " + tile_name({{i, j}}) + ": channel count differs from tile 0,0");
                        for (int c = 0; c < f.channels(); ++c)
                            for (int y = 0; y < r.height(); ++y) {
                                const float* s = f.channel(c).data() + f.index(0, y);
                                std::copy(s, s + r.width(), dst.channel(c).data() + dst.index(r.x0, r.y0 + y));
                            }
                    } else if (auto t3 = std::get_if<Field3DPtr>(&v)) {
                        const Field3D& f = **t3;
                        if (f.nx() != r.width() || f.ny() != r.height()) throw Error("tile " + tile_name({{i, j}}) + ": '" + raw.string() + "' has the wrong size");
                        if (full2) throw Error("tile " + tile_name({{i, j}}) + ": a 3D tile among 2D ones");
                        if (!full3) {
                            Box3d b{{{gb.min[0], gb.min[1], f.bounds().min[2]}}, {{gb.max[0], gb.max[1], f.bounds().max[2]}}};
                            full3 = std::make_shared<Field3D>(Vec3i{{grid.res[0], grid.res[1], f.nz()}}, f.channels(), b, f.channel_names(), &budget);
                        }
                        Field3D& dst = *full3;
                        if (dst.channels() != f.channels() || dst.nz() != f.nz()) throw Error("tile " + tile_name({{i, j}}) + ": shape differs from tile 0,0");
                        for (int c = 0; c < f.channels(); ++c)
                            for (int z = 0; z < f.nz(); ++z)
                                for (int y = 0; y < r.height(); ++y) {
                                    const float* s = f.channel(c).data() + f.index(0, y, z);
                                    std::copy(s, s + r.width(), dst.channel(c).data() + dst.index(r.x0, r.y0 + y, z));
                                }
                    } else {
                        throw Error("tile " + tile_name({{i, j}}) + ": '" + raw.string() + "' holds no field");
                    }
                }
            StagedOutputs& st = staged_in(staging, u.place.root);
            const Value full = full2 ? Value(Field2DPtr(full2)) : Value(Field3DPtr(full3));
            std::vector<fs::path> finals;
            for (const auto& f : io::write_value(full, st.stage(u.place.rel), o->format, o->options, nullptr)) finals.push_back(st.final_path(f));
            result.assembled.insert(result.assembled.end(), finals.begin(), finals.end());
            written.push_back({u, std::move(finals)});
        } catch (const CancelledError&) {
            throw;
        } catch (const MemoryBudgetError& e) {
            // Past the budget the tiles are the product: they and the index are already written.
            throw MemoryBudgetError(o->where.str() + ": assembling output '" + o->file + "': " + e.what() + "; its tiles and '" +
                                    (root / "tiles" / "index.json").string() + "' are written and complete: stream the tiles (docs/scale.md), " +
                                    "and assemble only worlds that fit");
        } catch (const std::exception& e) {
            throw Error(o->where.str() + ": assembling output '" + o->file + "': " + e.what());
        }
    }
    commit_all(staging);
    for (auto& [u, finals] : written) record(u, finals);
    save_records();
}

} // namespace

std::string tiled_report_json(const TiledCookResult& r, const std::string& graph_file, const std::string& status, const std::string& error) {
    json doc;
    doc["atlas_report_version"] = 1;
    doc["graph"] = graph_file;
    doc["status"] = status;
    if (status != "ok") {
        json e{{"message", error}};
        for (const auto& t : r.tiles_done)
            if (t.status == "failed" || t.status == "cancelled") e["tile"] = {t.tile[0], t.tile[1]};
        doc["error"] = e;
    }
    doc["seconds"] = r.seconds;
    doc["jobs"] = r.jobs;
    doc["tiled"] = {{"tiles", {r.tiles[0], r.tiles[1]}}, {"grid", {r.grid[0], r.grid[1]}}};
    if (!r.warnings.empty()) doc["warnings"] = r.warnings;
    std::vector<const TileReport*> order;
    for (const auto& t : r.tiles_done) order.push_back(&t);
    std::stable_sort(order.begin(), order.end(), [](const TileReport* a, const TileReport* b) {
        return std::pair(a->tile[1], a->tile[0]) < std::pair(b->tile[1], b->tile[0]);
    });
    json tiles = json::array();
    json summary = {{"cooked", 0}, {"up to date", 0}, {"failed", 0}};
    double cpu = 0;
    uint64_t value_peak = 0, rss_peak = 0;
    for (const TileReport* t : order) {
        json jt = {{"tile", {t->tile[0], t->tile[1]}},
                   {"texels", {t->texels.x0, t->texels.y0, t->texels.x1, t->texels.y1}},
                   {"status", t->status},
                   {"seconds", t->seconds},
                   {"cpu_seconds", t->cpu_seconds},
                   {"value_bytes_peak", t->value_bytes_peak},
                   {"rss_peak_bytes", t->rss_peak_bytes}};
        if (!t->error.empty()) jt["error"] = t->error;
        json files = json::array();
        for (const auto& f : t->files) files.push_back({{"path", f.path}, {"bytes", f.bytes}, {"hash", f.hash}, {"sha256", f.sha256}});
        jt["files"] = files;
        tiles.push_back(jt);
        const std::string k = t->status == "cancelled" ? "failed" : t->status;
        if (summary.contains(k)) summary[k] = summary[k].get<int>() + 1;
        cpu += t->cpu_seconds;
        value_peak = std::max(value_peak, t->value_bytes_peak);
        rss_peak = std::max(rss_peak, t->rss_peak_bytes);
    }
    doc["tiles"] = tiles;
    if (!r.index.empty()) doc["index"] = r.index.generic_string();
    json assembled = json::array();
    for (const auto& p : r.assembled) assembled.push_back(p.generic_string());
    doc["assembled"] = assembled;
    summary["cpu_seconds"] = cpu;
    summary["value_bytes_peak"] = value_peak;
    summary["rss_peak_bytes"] = rss_peak;
    doc["summary"] = summary;
    return doc.dump(2) + "\n";
}

TileRect tile_rect(Vec2i grid, Vec2i tiles, Vec2i t) {
    const int w = grid[0] / tiles[0], h = grid[1] / tiles[1];
    return {t[0] * w, t[1] * h, (t[0] + 1) * w, (t[1] + 1) * h};
}

void check_tileable(const Session& session, const std::vector<std::string>& outputs) {
    make_plan(session.graph(), session.registry(), outputs);
}

TiledCookResult cook_tiled(Session& session, const CookOptions& opt, const TileOptions& topt) {
    TiledCookResult result;
    cook_tiled(session, opt, topt, result);
    return result;
}

void cook_tiled(Session& session, const CookOptions& opt, const TileOptions& topt, TiledCookResult& result) {
    TiledCook cook(session, opt, topt, result);
    cook.select_tiles();
    cook.cook_sources();
    cook.check_grid();
    cook.cook_tiles();
    if (!topt.only) {
        cook.write_index();
        if (topt.assemble) cook.assemble();
    }
    result.seconds = seconds_since(cook.t_start);
}

} // namespace atlas
