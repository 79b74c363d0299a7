// Internal to graph: the parts of a tiled cook (tiling.cpp) that are not its steps: what a
// tiled cook cooks (the plan), the tile grid's geometry and crops, and the tiles' file names,
// fragments and reports (docs/scale.md). Implemented in tile_parts.cpp.
#pragma once

#include "atlas/core/files.h"
#include "atlas/core/value.h"
#include "atlas/graph/graph.h"
#include "atlas/graph/node.h"
#include "atlas/graph/tiling.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace atlas::detail::tiles {

using json = nlohmann::json;

namespace fs = std::filesystem;

std::string tile_name(Vec2i t);

// What made a tile (issue 46 item 5): the build, and the CPU's vector paths as the kernels
// choose them (ATLAS_SIMD forces the portable ones). Tiles of one world cooked on different
// machines have the same bytes (tests/cli/portable_simd_test.sh); this says where each came from.
json made_by();

// What the requested outputs need: the outputs and the nodes, inputs first.
struct Plan {
    std::vector<const GraphOutput*> outputs;
    std::vector<const GraphNode*> order; // the nodes cooked per tile, inputs first
    // Values passed whole to every tile (TileRule::whole_inputs): node and port.
    // They and what feeds them are cooked once through the session, untiled.
    std::set<std::pair<std::string, std::string>> aside;
    // Tiled nodes without tiled inputs (generators, and nodes whose inputs are all passed whole).
    std::set<std::string> sources;
    std::map<std::string, int> halo; // per node
    std::set<std::string> grid_halo;  // nodes whose halo needs the grid (computed once it is known)
    std::set<std::string> reads_window; // nodes that get their input window (CookContext::window())
    std::map<std::string, TileGrid> windowed; // generators that cook each tile's window themselves
    std::map<std::string, std::string> last_use; // node -> the last node (in order) that reads it
    // node -> its ports that tiled nodes read through inputs that are not passed whole
    std::map<std::string, std::set<std::string>> tiled_reads;
    std::set<std::string> output_nodes;
};

std::string node_label(const GraphNode& n);

Plan make_plan(const Graph& g, const NodeRegistry& reg, const std::vector<std::string>& wanted);

// ----------------------------------------------------------------- geometry

struct Grid {
    Vec2i res{{0, 0}};
    Vec2d lo{{0, 0}}, hi{{0, 0}};
    std::string from; // the node that set it
};

TileWindow window_of(const Grid& g, const TileRect& r);

Box2d rect_bounds(const Grid& g, const TileRect& r);

TileRect grow(const TileRect& r, int h, Vec2i res);

TileRect unite(const TileRect& a, const TileRect& b);

// A held value: a field over `rect` of the grid, or a value that is not
// tiled (passed whole).
struct Held {
    Value v;
    TileRect rect;
    bool whole = false;
};

// Held values by node and port.
using HeldValues = std::map<std::pair<std::string, std::string>, Held>;

Value crop(const Value& v, const TileRect& have, const TileRect& want, const Grid& g, const MemoryBudget& budget);

bool is_field(const Value& v);

// XY resolution and bounds of a field value.
void field_xy(const Value& v, Vec2i& res, Vec2d& lo, Vec2d& hi);

std::string xy_text(Vec2i r);

// --------------------------------------------------------------- file names

// tiles/DIR/STEM.I_J.EXT for output DIR/STEM.EXT.
fs::path tile_rel(const GraphOutput& o, Vec2i t);

fs::path fragment_rel(Vec2i t);

json file_entry(const fs::path& root, const fs::path& final_path, const fs::path& on_disk);

// A range in a fragment: {+inf, -inf} (no stored channel) as null, which JSON has no number for.
json range_json(std::pair<float, float> r);

std::optional<std::pair<float, float>> range_of(const json& j);

// A fragment's files are all present with the recorded sizes and hashes.
bool files_current(const fs::path& root, const json& files);

std::optional<json> current_fragment(const fs::path& root, Vec2i t, const std::string& key);

json grid_json(const Grid& g);

Grid grid_from_json(const json& j);

// Bytes of the values, each field counted once (crops that are the whole value share it).
uint64_t distinct_bytes(const std::vector<Value>& values);

// A tile's report: its files are those its fragment lists, and the fragment.
TileReport tile_report(Vec2i t, TileRect texels, std::string status, double seconds, double cpu, uint64_t value_peak, const json* frag,
                       const fs::path& root);

// The tile counts and the one tile asked for are in range.
void check_tile_counts(const TileOptions& topt);

} // namespace atlas::detail::tiles
