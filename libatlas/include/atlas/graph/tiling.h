// atlas/graph/tiling.h - cooking a graph's world-space outputs in XY tiles.
//
// `atlas cook GRAPH --tiles NX,NY [--tile I,J] [--assemble]` (docs/scale.md).
// Every node an output needs declares how it tiles (TileRule in node.h);
// the tiled cook derives, for one tile of the output grid, the region each
// upstream node must cook (the tile grown by the halos of the nodes between,
// clipped to the grid), cooks that region and crops. Generators (nodes
// without inputs) are cooked whole through the session (memory and disk
// cache) and cropped. Each tile writes, under OUT/tiles/, its files in each
// output's own format, an exact copy of the tile's values (.atlastile, for
// assembling) and a fragment I_J.json naming them with their hashes; all of
// one tile are committed together, so a failed tile leaves nothing. When every
// tile is present, OUT/tiles/index.json (the tile index an engine streams)
// is written, and `assemble` writes the untiled outputs, byte for byte the
// files one untiled cook writes.
#pragma once

#include "atlas/graph/evaluator.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace atlas {

constexpr int kTileFormatVersion = 2; // 2: outputs quantised by their own range share the world's ("own_range", "range")

// A texel rectangle [x0, x1) x [y0, y1) of the tiled XY grid.
struct TileRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    bool operator==(const TileRect&) const = default;
};

// Tile (i, j) of `tiles` over a grid of `grid` texels (the grid must divide evenly).
TileRect tile_rect(Vec2i grid, Vec2i tiles, Vec2i tile);

struct TileOptions {
    Vec2i tiles{{1, 1}};       // NX, NY
    std::optional<Vec2i> only; // cook this tile only (no index, no assembly)
    bool assemble = false;     // when every tile is present: write the untiled outputs
    // Each tile also writes an exact copy of its values (.atlastile), which assembling reads.
    // Without them the tiles are the product: far less to write for a world too big to assemble.
    bool exact_values = true;
    std::string graph_name;    // recorded in the index
};

struct TileFileReport {
    std::string path;   // relative to the output directory
    uint64_t bytes = 0;
    std::string hash;   // file_content_hash, hex
    std::string sha256;
};

struct TileReport {
    Vec2i tile{{0, 0}};
    TileRect texels;
    // "cooked", "up to date" (its fragment and files were current) or
    // "failed" (`error` says why; nothing of the tile was written).
    std::string status;
    std::string error;
    double seconds = 0;          // wall time of the tile (0 when up to date)
    double cpu_seconds = 0;      // process CPU time (user + system) spent on it
    uint64_t value_bytes_peak = 0; // most bytes of node values held at once on the tile
    uint64_t rss_peak_bytes = 0;   // the process's peak resident set when the tile ended
    std::vector<TileFileReport> files; // the tile's files (outputs, exact values, fragment)
};

struct TiledCookResult {
    Vec2i grid{{0, 0}}; // texels of the tiled XY grid
    Vec2i tiles{{1, 1}};
    std::vector<TileReport> tiles_done;
    std::vector<std::filesystem::path> written; // every file this call wrote
    std::filesystem::path index;                // the tile index, when written
    std::vector<std::filesystem::path> assembled; // the untiled outputs written by assembling
    int jobs = 0;
    double seconds = 0;
    // What the cook did that works but costs: a node whose halo is wider than a tile (each
    // tile then cooks it over most of the grid), named with its place.
    std::vector<std::string> warnings;
};

// Throws atlas::Error (naming file:line:col, the node and its type) for the
// first node the requested outputs need that cannot tile with its parameters,
// or an output that is not a field.
void check_tileable(const Session& session, const std::vector<std::string>& outputs);

// Cooks the tiles (one or all) and writes them; see the top of this file.
// Errors name the tile ("tile 1,0: node 'blur' (ndf/blur): ...").
TiledCookResult cook_tiled(Session& session, const CookOptions& options, const TileOptions& tiles);

// The same, filling `result` as it goes, so that after an error it holds
// the tiles done before and the failed tile (status "failed", its error)
// for a report; then the error is rethrown.
void cook_tiled(Session& session, const CookOptions& options, const TileOptions& tiles, TiledCookResult& result);

// The --report document of a tiled cook (docs/report.md, "Tiled cooks").
// `status` is "ok", "failed" or "cancelled"; `error` the message when not ok.
std::string tiled_report_json(const TiledCookResult& result, const std::string& graph_file, const std::string& status,
                              const std::string& error);

} // namespace atlas
