// atlas/graph/node.h - how a node type declares itself and cooks.
//
// A node type is a declaration (ports, parameters, docs) plus a stateless
// cook function, in one file under nodes/ (see nodes/field/constant.cpp):
//
//   static void declare(NodeDeclaration& d) { d.doc(...); d.output(...); d.param_float(...); }
//   static void cook(CookContext& ctx) { ... ctx.set_output("out", field); }
//   ATLAS_REGISTER_NODE(registry) {
//       registry.add({.name = "field/constant", .version = 1, .declare = declare, .cook = cook});
//   }
//
// The build generates the list of node files, so adding a node never edits a
// central list. cook() must read only its parameters and inputs (and, if
// hash_extra says so, files): that is what makes the content hash complete,
// and checked mode (CookOptions::checked) verifies it.
#pragma once

#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/progress.h"
#include "atlas/core/value.h"
#include "atlas/graph/param.h"

#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace atlas {

struct PortDecl {
    std::string name;
    PortType type = PortType::Field;
    std::string doc;
    bool optional = false;
};

class NodeParams;

// How a node cooks in tiles (atlas cook --tiles, docs/scale.md). The default
// is "does not tile": a graph that needs such a node is refused for tiling
// with a message naming it. A node without inputs that declares pointwise is
// cooked whole and cropped (exact for any generator); a node with inputs is
// cooked on cropped inputs: pointwise ones on the tile itself, halo ones on
// the tile grown by halo() texels/voxels in x and y (clipped to the grid),
// and their result is cropped back. Such a node must compute each output
// voxel from its own index's neighbourhood only (never from the field's
// world bounds or extent), so the crop of its result equals the crop of the
// untiled result bit for bit.
// The full XY grid a node's output covers (resolution and world bounds).
struct TileGrid {
    Vec2i res{{0, 0}};
    Box2d bounds;
};

// A window of a node's full XY grid that a tiled cook asks a generator for
// (CookContext::window()): texels [x0, x1) x [y0, y1), all of z. The field it
// makes has resolution size() in x, y and XY bounds bounds(), and each voxel
// holds what voxel (x0 + i, y0 + j, k) of the whole grid would hold.
struct TileWindow {
    TileGrid grid;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    Vec2i size() const { return {{x1 - x0, y1 - y0}}; }
    static double edge(double lo, double hi, int i, int n) { return XYWindow::edge(lo, hi, i, n); }
    Box2d bounds() const {
        const Box2d& b = grid.bounds;
        return {{{edge(b.min[0], b.max[0], x0, grid.res[0]), edge(b.min[1], b.max[1], y0, grid.res[1])}},
                {{edge(b.min[0], b.max[0], x1, grid.res[0]), edge(b.min[1], b.max[1], y1, grid.res[1])}}};
    }
};

struct TileRule {
    // Whole: the node needs its whole input (a distance map, a map-wide stencil): it and
    // what feeds it are cooked whole once per process and cropped to each tile.
    enum class Kind { None, Pointwise, Halo, Whole };
    Kind kind = Kind::None;
    std::function<int(const NodeParams&)> halo;           // Halo: texels/voxels in x and y
    std::function<std::string(const NodeParams&)> refuse; // optional: why these parameters cannot tile ("" = they can)
    std::string why_not;                                  // None: why the node does not tile; Whole: why it is cooked whole
    // Optional, for generators: the grid the node makes with these
    // parameters when its cook honours CookContext::window() for them
    // (nullopt: it is cooked whole and cropped). Only such generators keep a
    // tile's memory to the tile: the others are cooked whole once per process.
    std::function<std::optional<TileGrid>(const NodeParams&)> window_grid;
    // Optional, for Halo: a halo that depends on the tiled grid's texel size
    // as well (e.g. a distance in metres); used instead of `halo` when set.
    std::function<int(const NodeParams&, const TileGrid&)> grid_halo;
    // The node's cook reads CookContext::window() in a tiled cook: the window
    // of the whole grid its inputs cover (the region grown by the halo), so it
    // can use the whole grid's texel size and tell the grid's own faces from a
    // crop's (null in an untiled cook).
    bool reads_window = false;
    // Inputs on any grid of their own (a cloud composited into the world, a
    // cutter): passed whole to every tile; the nodes feeding them are cooked
    // whole once per process and need no tiling rule.
    std::set<std::string> whole_inputs;

    TileRule& windowed(std::function<std::optional<TileGrid>(const NodeParams&)> grid) {
        window_grid = std::move(grid);
        return *this;
    }

    static TileRule pointwise(std::function<std::string(const NodeParams&)> refuse = {}) {
        TileRule r;
        r.kind = Kind::Pointwise;
        r.refuse = std::move(refuse);
        return r;
    }
    static TileRule with_halo(std::function<int(const NodeParams&)> halo, std::function<std::string(const NodeParams&)> refuse = {}) {
        TileRule r;
        r.kind = Kind::Halo;
        r.halo = std::move(halo);
        r.refuse = std::move(refuse);
        return r;
    }
    static TileRule with_grid_halo(std::function<int(const NodeParams&, const TileGrid&)> halo,
                                   std::function<std::string(const NodeParams&)> refuse = {}) {
        TileRule r;
        r.kind = Kind::Halo;
        r.grid_halo = std::move(halo);
        r.refuse = std::move(refuse);
        return r;
    }
    TileRule& with_window() {
        reads_window = true;
        return *this;
    }
    TileRule& whole_input(std::string port) {
        whole_inputs.insert(std::move(port));
        return *this;
    }
    static TileRule whole(std::string why) {
        TileRule r;
        r.kind = Kind::Whole;
        r.why_not = std::move(why);
        return r;
    }
    static TileRule none(std::string why) {
        TileRule r;
        r.why_not = std::move(why);
        return r;
    }
};

class NodeDeclaration {
public:
    NodeDeclaration& doc(std::string text) { doc_ = std::move(text); return *this; }
    NodeDeclaration& category(std::string c) { category_ = std::move(c); return *this; }
    NodeDeclaration& tiling(TileRule rule) { tiling_ = std::move(rule); return *this; }
    const TileRule& tiling() const { return tiling_; }

    PortDecl& input(std::string name, PortType type, std::string doc);
    PortDecl& output(std::string name, PortType type, std::string doc);

    ParamDecl& param_float(std::string name, double def);
    ParamDecl& param_int(std::string name, int64_t def);
    ParamDecl& param_bool(std::string name, bool def);
    ParamDecl& param_string(std::string name, std::string def);
    ParamDecl& param_enum(std::string name, std::vector<std::string> choices, std::string def);
    ParamDecl& param_path(std::string name, std::string def = "");
    ParamDecl& param_float2(std::string name, Vec2d def);
    ParamDecl& param_float3(std::string name, Vec3d def);
    ParamDecl& param_int2(std::string name, Vec2i def);
    ParamDecl& param_int3(std::string name, Vec3i def);

    const std::string& doc() const { return doc_; }
    const std::deque<PortDecl>& inputs() const { return inputs_; }
    const std::deque<PortDecl>& outputs() const { return outputs_; }
    const std::deque<ParamDecl>& params() const { return params_; }
    const PortDecl* find_input(const std::string& n) const;
    const PortDecl* find_output(const std::string& n) const;
    const ParamDecl* find_param(const std::string& n) const;

private:
    ParamDecl& add_param(ParamDecl p);
    std::string doc_, category_;
    // deque: references returned by the builders stay valid as more are added.
    std::deque<PortDecl> inputs_, outputs_;
    std::deque<ParamDecl> params_;
    TileRule tiling_;
};

// The resolved parameters of one node instance (explicit values over
// defaults), with typed getters. Getters throw atlas::Error on a name the
// node did not declare (a programming error in the node file).
class NodeParams {
public:
    NodeParams(const NodeDeclaration* decl, std::map<std::string, ParamValue> values, std::filesystem::path base_dir);

    double get_float(const std::string& name) const;
    int64_t get_int(const std::string& name) const;
    bool get_bool(const std::string& name) const;
    const std::string& get_string(const std::string& name) const; // String and Enum
    Vec2d get_float2(const std::string& name) const;
    Vec3d get_float3(const std::string& name) const;
    Vec2i get_int2(const std::string& name) const;
    Vec3i get_int3(const std::string& name) const;
    // A Path parameter resolved against the graph file's directory.
    std::filesystem::path get_path(const std::string& name) const;

    const ParamValue& get(const std::string& name) const;
    const std::map<std::string, ParamValue>& values() const { return values_; }

private:
    const ParamValue& checked(const std::string& name, ParamType a, ParamType b) const;
    const NodeDeclaration* decl_;
    std::map<std::string, ParamValue> values_;
    std::filesystem::path base_dir_;
};

// Everything a cook function may use. Not thread-safe itself; one per cook.
class CookContext {
public:
    CookContext(std::string node_name, std::string node_type, const NodeDeclaration& decl, const NodeParams& params,
                std::map<std::string, Value> inputs, const MemoryBudget& budget, const ProgressSink& progress);

    const std::string& node_name() const { return name_; }
    const NodeParams& params() const { return params_; }
    double get_float(const std::string& n) const { return params_.get_float(n); }
    int64_t get_int(const std::string& n) const { return params_.get_int(n); }
    bool get_bool(const std::string& n) const { return params_.get_bool(n); }
    const std::string& get_string(const std::string& n) const { return params_.get_string(n); }
    Vec3d get_float3(const std::string& n) const { return params_.get_float3(n); }
    Vec2d get_float2(const std::string& n) const { return params_.get_float2(n); }
    Vec3i get_int3(const std::string& n) const { return params_.get_int3(n); }
    Vec2i get_int2(const std::string& n) const { return params_.get_int2(n); }
    std::filesystem::path get_path(const std::string& n) const { return params_.get_path(n); }

    bool has_input(const std::string& port) const;
    const Value& input(const std::string& port) const;
    // Typed access; throws a clear error naming the node and port when the
    // input is missing or of another type.
    Field2DPtr input_field2d(const std::string& port) const;
    Field3DPtr input_field3d(const std::string& port) const;
    MeshPtr input_mesh(const std::string& port) const;
    PointsPtr input_points(const std::string& port) const;

    void set_output(const std::string& port, Value v);
    const std::map<std::string, Value>& outputs() const { return outputs_; }

    // Memory: new fields checked against the budget, named after this node.
    std::shared_ptr<Field2D> make_field2d(Vec2i res, int channels, Box2d bounds, std::vector<std::string> names = {}) const;
    std::shared_ptr<Field3D> make_field3d(Vec3i res, int channels, Box3d bounds, std::vector<std::string> names = {}) const;
    void check_memory(uint64_t bytes, std::string_view what) const;
    const MemoryBudget& budget() const { return budget_; }

    // Progress within this node (0..1); also polls for cancellation.
    void progress(double fraction) const;
    const ProgressSink& progress_sink() const { return progress_; }

    // Error metrics and notes that go into the cook report.
    void metric(const std::string& name, double value) { metrics_[name] = value; }
    void warn(std::string message) { warnings_.push_back(std::move(message)); }
    const std::map<std::string, double>& metrics() const { return metrics_; }
    const std::vector<std::string>& warnings() const { return warnings_; }

    // An error about this node's parameter, e.g. error_param("radius", "must be > 0").
    [[noreturn]] void fail(const std::string& message) const;

    // In a tiled cook, the window of its grid a generator whose TileRule is
    // windowed() is asked for, or for a node whose TileRule reads_window the
    // window its inputs cover (null otherwise, and in an untiled cook).
    const TileWindow* window() const { return window_; }
    void set_window(const TileWindow* w) { window_ = w; }
    // Where a field on the tiled grid (an input or an output made like one)
    // sits in the whole grid: its own frame untiled, the window's in a tiled
    // cook (z is never tiled). Positions and voxel sizes taken from it are
    // the untiled cook's to the last bit.
    GridFrame frame(const Field3D& f) const;

private:
    std::string name_, type_;
    const NodeDeclaration& decl_;
    const NodeParams& params_;
    std::map<std::string, Value> inputs_;
    std::map<std::string, Value> outputs_;
    const MemoryBudget& budget_;
    const ProgressSink& progress_;
    std::map<std::string, double> metrics_;
    std::vector<std::string> warnings_;
    const TileWindow* window_ = nullptr;
};

class Hasher;

struct NodeType {
    std::string name; // "category/name", matching its file nodes/category/name.cpp
    int version = 1;  // bump when cook() changes its results: invalidates caches
    std::function<void(NodeDeclaration&)> declare;
    std::function<void(CookContext&)> cook;
    // Optional: adds what cook() reads beyond parameters and inputs (e.g. the
    // contents of an input file) to the node's content hash.
    std::function<void(const NodeParams&, Hasher&)> hash_extra;
    // Filled by the registry.
    NodeDeclaration decl;
};

class NodeRegistry {
public:
    // Runs the type's declare() and stores it. Throws on a duplicate name.
    void add(NodeType type);
    const NodeType* find(const std::string& name) const;
    // All types sorted by name.
    std::vector<const NodeType*> all() const;
    std::vector<std::string> names() const;

private:
    std::map<std::string, NodeType> types_;
};

// The node types built into Atlas (every file under nodes/). Returns a new
// registry each call: there is no global registry. Defined in the file nodes/CMakeLists.txt
// generates from the node sources (build/nodes/builtin_nodes.cpp).
NodeRegistry builtin_nodes();

} // namespace atlas

#define ATLAS_NODE_CAT2(a, b) a##b
#define ATLAS_NODE_CAT(a, b) ATLAS_NODE_CAT2(a, b)
// ATLAS_NODE_ID is defined by the build for each file under nodes/.
#define ATLAS_REGISTER_NODE(registry) \
    void ATLAS_NODE_CAT(atlas_register_node_, ATLAS_NODE_ID)(::atlas::NodeRegistry & registry)
