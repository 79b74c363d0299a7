// The parts of a tiled cook (tile_parts.h): the plan, the grid's geometry and crops, the
// tiles' file names, fragments and reports.
#include "tile_parts.h"
#include "cook_steps.h"
#include "graph_walk.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/core/progress.h"
#include "atlas/graph/node_docs.h"

#include <algorithm>
#include <cstdlib>

namespace atlas::detail::tiles {

std::string tile_name(Vec2i t) { return std::to_string(t[0]) + "," + std::to_string(t[1]); }

json made_by() {
    const char* forced = std::getenv("ATLAS_SIMD");
    return {{"atlas", ATLAS_VERSION_STRING},
#if defined(__clang__)
            {"compiler", "clang " __clang_version__},
#elif defined(__GNUC__)
            {"compiler", "gcc " __VERSION__},
#endif
#if defined(__x86_64__)
            {"cpu_avx2", bool(__builtin_cpu_supports("avx2"))},
            {"cpu_avx512f", bool(__builtin_cpu_supports("avx512f"))},
#endif
            {"atlas_simd", forced ? forced : "auto"}};
}

using detail::source_port;

using detail::topological_order;

std::string node_label(const GraphNode& n) {
    return (n.where.str().empty() ? "" : n.where.str() + ": ") + "node '" + n.name + "' (" + n.type + ")";
}

Plan make_plan(const Graph& g, const NodeRegistry& reg, const std::vector<std::string>& wanted) {
    Plan p;
    p.outputs = detail::select_outputs(g, wanted);
    if (p.outputs.empty()) throw Error("tiling: the graph writes no outputs");
    std::vector<std::string> targets;
    for (const GraphOutput* o : p.outputs) targets.push_back(o->node);
    // The nodes an output reaches through inputs that are not passed whole tile;
    // the rest (a cloud on its own grid and its sources) are cooked whole.
    const std::vector<const GraphNode*> needed = detail::needed_nodes(g, targets);
    std::set<std::string> tiled(targets.begin(), targets.end());
    for (auto it = needed.rbegin(); it != needed.rend(); ++it) {
        const GraphNode& n = **it;
        if (!tiled.count(n.name)) continue;
        const TileRule& rule = reg.find(n.type)->decl.tiling();
        if (rule.kind == TileRule::Kind::Whole) continue; // the session cooks what it reads
        for (const auto& [port, b] : n.inputs) {
            if (rule.whole_inputs.count(port)) p.aside.insert({b.node, source_port(g, reg, b)});
            else tiled.insert(b.node);
        }
    }
    for (const GraphNode* n : needed) {
        if (!tiled.count(n->name)) continue;
        p.order.push_back(n);
        const TileRule& rule = reg.find(n->type)->decl.tiling();
        if (rule.kind == TileRule::Kind::Whole ||
            std::all_of(n->inputs.begin(), n->inputs.end(), [&](const auto& in) { return rule.whole_inputs.count(in.first) > 0; }))
            p.sources.insert(n->name);
    }
    for (const GraphNode* n : p.order) {
        const TileRule& rule = reg.find(n->type)->decl.tiling();
        for (const auto& [port, b] : n->inputs) {
            p.last_use[b.node] = n->name;
            if (!rule.whole_inputs.count(port)) p.tiled_reads[b.node].insert(source_port(g, reg, b));
        }
    }
    for (const GraphOutput* o : p.outputs) p.output_nodes.insert(o->node);

    for (const GraphOutput* o : p.outputs) {
        const NodeType* t = reg.find(g.find(o->node)->type);
        const PortDecl* port = t->decl.find_output(o->port);
        if (port && (port->type == PortType::Mesh || port->type == PortType::Points))
            throw Error(o->where.str() + ": output '" + o->file + "' writes a " + std::string(port_type_name(port->type)) +
                        ", which does not tile (only fields do)");
    }
    for (const GraphNode* n : p.order) {
        const NodeType* t = reg.find(n->type);
        const TileRule& rule = t->decl.tiling();
        if (rule.kind == TileRule::Kind::None) throw Error(node_label(*n) + " cannot be cooked in tiles: " + tiling_refusal(t->decl));
        NodeParams params(&t->decl, resolved_params(*n, *t), g.base_dir);
        if (rule.refuse)
            if (std::string why = rule.refuse(params); !why.empty()) throw Error(node_label(*n) + " cannot be cooked in tiles: " + why);
        int h = 0;
        if (rule.kind == TileRule::Kind::Halo && !p.sources.count(n->name)) {
            if (rule.grid_halo) p.grid_halo.insert(n->name);
            else h = rule.halo(params);
        }
        if (rule.reads_window && !p.sources.count(n->name)) p.reads_window.insert(n->name);
        if (h < 0) throw Error(node_label(*n) + ": internal: negative tiling halo");
        p.halo[n->name] = h;
        if (p.sources.count(n->name) && rule.window_grid)
            if (auto grid = rule.window_grid(params)) p.windowed[n->name] = *grid;
    }
    return p;
}

TileWindow window_of(const Grid& g, const TileRect& r) { return {{g.res, {g.lo, g.hi}}, r.x0, r.y0, r.x1, r.y1}; }

Box2d rect_bounds(const Grid& g, const TileRect& r) { return window_of(g, r).bounds(); }

TileRect grow(const TileRect& r, int h, Vec2i res) {
    return {std::max(0, r.x0 - h), std::max(0, r.y0 - h), std::min(res[0], r.x1 + h), std::min(res[1], r.y1 + h)};
}

TileRect unite(const TileRect& a, const TileRect& b) {
    if (a.empty()) return b;
    if (b.empty()) return a;
    return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

Value crop(const Value& v, const TileRect& have, const TileRect& want, const Grid& g, const MemoryBudget& budget) {
    if (have == want) return v;
    const Box2d b = rect_bounds(g, want);
    const int ox = want.x0 - have.x0, oy = want.y0 - have.y0, w = want.width(), h = want.height();
    if (auto f2 = std::get_if<Field2DPtr>(&v)) {
        const Field2D& f = **f2;
        auto out = std::make_shared<Field2D>(Vec2i{{w, h}}, f.channels(), b, f.channel_names(), &budget);
        for (int c = 0; c < f.channels(); ++c)
            for (int y = 0; y < h; ++y) {
                const float* src = f.channel(c).data() + f.index(ox, oy + y);
                std::copy(src, src + w, out->channel(c).data() + out->index(0, y));
            }
        return Field2DPtr(out);
    }
    const Field3D& f = *std::get<Field3DPtr>(v);
    Box3d b3{{{b.min[0], b.min[1], f.bounds().min[2]}}, {{b.max[0], b.max[1], f.bounds().max[2]}}};
    auto out = std::make_shared<Field3D>(Vec3i{{w, h, f.nz()}}, f.channels(), b3, f.channel_names(), &budget);
    for (int c = 0; c < f.channels(); ++c)
        for (int z = 0; z < f.nz(); ++z)
            for (int y = 0; y < h; ++y) {
                const float* src = f.channel(c).data() + f.index(ox, oy + y, z);
                std::copy(src, src + w, out->channel(c).data() + out->index(0, y, z));
            }
    return Field3DPtr(out);
}

bool is_field(const Value& v) { return std::holds_alternative<Field2DPtr>(v) || std::holds_alternative<Field3DPtr>(v); }

void field_xy(const Value& v, Vec2i& res, Vec2d& lo, Vec2d& hi) {
    if (auto f2 = std::get_if<Field2DPtr>(&v)) {
        res = (*f2)->resolution();
        lo = (*f2)->bounds().min;
        hi = (*f2)->bounds().max;
    } else {
        const Field3D& f = *std::get<Field3DPtr>(v);
        res = {{f.nx(), f.ny()}};
        lo = {{f.bounds().min[0], f.bounds().min[1]}};
        hi = {{f.bounds().max[0], f.bounds().max[1]}};
    }
}

std::string xy_text(Vec2i r) { return std::to_string(r[0]) + " x " + std::to_string(r[1]); }

fs::path tile_rel(const GraphOutput& o, Vec2i t) {
    fs::path p = fs::path(o.file).lexically_normal();
    if (p.is_absolute() || (!p.empty() && p.begin()->string() == "..")) p = p.filename();
    const std::string tag = "." + std::to_string(t[0]) + "_" + std::to_string(t[1]);
    return fs::path("tiles") / p.parent_path() / (p.stem().string() + tag + p.extension().string());
}

fs::path fragment_rel(Vec2i t) { return fs::path("tiles") / (std::to_string(t[0]) + "_" + std::to_string(t[1]) + ".json"); }

json file_entry(const fs::path& root, const fs::path& final_path, const fs::path& on_disk) {
    return {{"path", final_path.lexically_relative(root).generic_string()},
            {"bytes", uint64_t(fs::file_size(on_disk))},
            {"hash", file_content_hash(on_disk).hex()},
            {"sha256", sha256_hex(read_file_bytes(on_disk))}};
}

json range_json(std::pair<float, float> r) {
    if (!(r.second >= r.first)) return nullptr;
    return {r.first, r.second};
}

std::optional<std::pair<float, float>> range_of(const json& j) {
    if (!j.is_array()) return std::nullopt;
    return std::make_pair(j.at(0).get<float>(), j.at(1).get<float>());
}

bool files_current(const fs::path& root, const json& files) {
    for (const auto& f : files) {
        const fs::path p = root / f.at("path").get<std::string>();
        std::error_code ec;
        if (fs::file_size(p, ec) != f.at("bytes").get<uint64_t>() || ec) return false;
        if (file_content_hash(p).hex() != f.at("hash").get<std::string>()) return false;
    }
    return true;
}

std::optional<json> current_fragment(const fs::path& root, Vec2i t, const std::string& key) {
    const fs::path p = root / fragment_rel(t);
    if (!fs::exists(p)) return std::nullopt;
    try {
        json j = json::parse(read_file_bytes(p));
        if (j.at("key").get<std::string>() != key) return std::nullopt;
        for (const auto& o : j.at("outputs")) {
            if (!files_current(root, o.at("files"))) return std::nullopt;
            if (o.contains("raw") && !files_current(root, json::array({o.at("raw")}))) return std::nullopt;
        }
        return j;
    } catch (const std::exception&) {
        return std::nullopt; // unreadable: the tile is cooked again
    }
}

json grid_json(const Grid& g) {
    return {{"resolution", {g.res[0], g.res[1]}}, {"bounds_min", {g.lo[0], g.lo[1]}}, {"bounds_max", {g.hi[0], g.hi[1]}}};
}

Grid grid_from_json(const json& j) {
    Grid g;
    g.res = {{j.at("resolution")[0].get<int>(), j.at("resolution")[1].get<int>()}};
    g.lo = {{j.at("bounds_min")[0].get<double>(), j.at("bounds_min")[1].get<double>()}};
    g.hi = {{j.at("bounds_max")[0].get<double>(), j.at("bounds_max")[1].get<double>()}};
    g.from = "the tile fragments";
    return g;
}

uint64_t distinct_bytes(const std::vector<Value>& values) {
    std::set<const void*> seen;
    uint64_t total = 0;
    for (const Value& v : values) {
        const void* p = nullptr;
        if (auto f2 = std::get_if<Field2DPtr>(&v)) p = f2->get();
        else if (auto f3 = std::get_if<Field3DPtr>(&v)) p = f3->get();
        if (p && !seen.insert(p).second) continue;
        total += value_bytes(v);
    }
    return total;
}

TileReport tile_report(Vec2i t, TileRect texels, std::string status, double seconds, double cpu, uint64_t value_peak, const json* frag,
                       const fs::path& root) {
    TileReport r;
    r.tile = t;
    r.texels = texels;
    r.status = std::move(status);
    r.seconds = seconds;
    r.cpu_seconds = cpu;
    r.value_bytes_peak = value_peak;
    r.rss_peak_bytes = process_peak_rss_bytes();
    if (!frag) return r;
    auto add = [&](const json& f) {
        r.files.push_back({f.at("path").get<std::string>(), f.at("bytes").get<uint64_t>(), f.at("hash").get<std::string>(),
                           f.value("sha256", std::string())});
    };
    std::set<std::string> seen;
    for (const auto& o : frag->at("outputs")) {
        for (const auto& f : o.at("files"))
            if (seen.insert(f.at("path").get<std::string>()).second) add(f);
        if (o.contains("raw") && seen.insert(o.at("raw").at("path").get<std::string>()).second) add(o.at("raw"));
    }
    const fs::path fp = root / fragment_rel(t);
    std::error_code ec;
    if (fs::exists(fp, ec)) add(file_entry(root, fp, fp));
    return r;
}

void check_tile_counts(const TileOptions& topt) {
    const Vec2i tiles = topt.tiles;
    if (tiles[0] < 1 || tiles[1] < 1 || tiles[0] > 4096 || tiles[1] > 4096)
        throw Error("--tiles " + tile_name(tiles) + ": tile counts must be in [1, 4096]");
    if (topt.only && ((*topt.only)[0] < 0 || (*topt.only)[0] >= tiles[0] || (*topt.only)[1] < 0 || (*topt.only)[1] >= tiles[1]))
        throw Error("--tile " + tile_name(*topt.only) + " is out of range: --tiles " + tile_name(tiles) + " has tiles 0.." +
                    std::to_string(tiles[0] - 1) + ", 0.." + std::to_string(tiles[1] - 1));
    if (topt.only && topt.assemble) throw Error("--assemble needs every tile: it cannot be combined with --tile");
    if (topt.assemble && !topt.exact_values)
        throw Error("--assemble reads each tile's exact values, which --no-tile-values leaves out: use one or the other");
}

} // namespace atlas::detail::tiles
