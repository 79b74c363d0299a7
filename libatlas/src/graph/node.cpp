#include "atlas/graph/node.h"
#include "atlas/core/memory_ledger.h"

#include "atlas/core/hash.h"

#include <algorithm>

namespace atlas {

PortDecl& NodeDeclaration::input(std::string name, PortType type, std::string doc) {
    inputs_.push_back({std::move(name), type, std::move(doc), false});
    return inputs_.back();
}

PortDecl& NodeDeclaration::output(std::string name, PortType type, std::string doc) {
    outputs_.push_back({std::move(name), type, std::move(doc), false});
    return outputs_.back();
}

ParamDecl& NodeDeclaration::add_param(ParamDecl p) {
    if (find_param(p.name)) throw Error("internal: parameter '" + p.name + "' declared twice");
    params_.push_back(std::move(p));
    return params_.back();
}

ParamDecl& NodeDeclaration::param_float(std::string name, double def) { return add_param({std::move(name), ParamType::Float, def}); }
ParamDecl& NodeDeclaration::param_int(std::string name, int64_t def) { return add_param({std::move(name), ParamType::Int, def}); }
ParamDecl& NodeDeclaration::param_bool(std::string name, bool def) { return add_param({std::move(name), ParamType::Bool, def}); }
ParamDecl& NodeDeclaration::param_string(std::string name, std::string def) {
    return add_param({std::move(name), ParamType::String, std::move(def)});
}
ParamDecl& NodeDeclaration::param_enum(std::string name, std::vector<std::string> choices, std::string def) {
    ParamDecl p{std::move(name), ParamType::Enum, std::move(def)};
    p.choices = std::move(choices);
    return add_param(std::move(p));
}
ParamDecl& NodeDeclaration::param_path(std::string name, std::string def) { return add_param({std::move(name), ParamType::Path, std::move(def)}); }
ParamDecl& NodeDeclaration::param_float2(std::string name, Vec2d d) {
    return add_param({std::move(name), ParamType::Float2, std::vector<double>{d[0], d[1]}});
}
ParamDecl& NodeDeclaration::param_float3(std::string name, Vec3d d) {
    return add_param({std::move(name), ParamType::Float3, std::vector<double>{d[0], d[1], d[2]}});
}
ParamDecl& NodeDeclaration::param_int2(std::string name, Vec2i d) {
    return add_param({std::move(name), ParamType::Int2, std::vector<double>{double(d[0]), double(d[1])}});
}
ParamDecl& NodeDeclaration::param_int3(std::string name, Vec3i d) {
    return add_param({std::move(name), ParamType::Int3, std::vector<double>{double(d[0]), double(d[1]), double(d[2])}});
}

const PortDecl* NodeDeclaration::find_input(const std::string& n) const {
    for (const auto& p : inputs_) if (p.name == n) return &p;
    return nullptr;
}
const PortDecl* NodeDeclaration::find_output(const std::string& n) const {
    for (const auto& p : outputs_) if (p.name == n) return &p;
    return nullptr;
}
const ParamDecl* NodeDeclaration::find_param(const std::string& n) const {
    for (const auto& p : params_) if (p.name == n) return &p;
    return nullptr;
}

// ---------------------------------------------------------------- NodeParams

NodeParams::NodeParams(const NodeDeclaration* decl, std::map<std::string, ParamValue> values, std::filesystem::path base_dir)
    : decl_(decl), values_(std::move(values)), base_dir_(std::move(base_dir)) {}

const ParamValue& NodeParams::get(const std::string& name) const {
    auto it = values_.find(name);
    if (it == values_.end()) throw Error("internal: node reads undeclared parameter '" + name + "'");
    return it->second;
}

const ParamValue& NodeParams::checked(const std::string& name, ParamType a, ParamType b) const {
    const ParamDecl* p = decl_ ? decl_->find_param(name) : nullptr;
    if (!p) throw Error("internal: node reads undeclared parameter '" + name + "'");
    if (p->type != a && p->type != b)
        throw Error("internal: parameter '" + name + "' is " + std::string(param_type_name(p->type)) + ", read as " +
                    std::string(param_type_name(a)));
    return get(name);
}

double NodeParams::get_float(const std::string& n) const {
    const auto& v = checked(n, ParamType::Float, ParamType::Int);
    return std::holds_alternative<int64_t>(v) ? double(std::get<int64_t>(v)) : std::get<double>(v);
}
int64_t NodeParams::get_int(const std::string& n) const { return std::get<int64_t>(checked(n, ParamType::Int, ParamType::Int)); }
bool NodeParams::get_bool(const std::string& n) const { return std::get<bool>(checked(n, ParamType::Bool, ParamType::Bool)); }
const std::string& NodeParams::get_string(const std::string& n) const {
    const ParamDecl* p = decl_ ? decl_->find_param(n) : nullptr;
    if (p && p->type == ParamType::Path) return std::get<std::string>(get(n));
    return std::get<std::string>(checked(n, ParamType::String, ParamType::Enum));
}
Vec2d NodeParams::get_float2(const std::string& n) const {
    const auto& v = std::get<std::vector<double>>(checked(n, ParamType::Float2, ParamType::Int2));
    return {{v[0], v[1]}};
}
Vec3d NodeParams::get_float3(const std::string& n) const {
    const auto& v = std::get<std::vector<double>>(checked(n, ParamType::Float3, ParamType::Int3));
    return {{v[0], v[1], v[2]}};
}
Vec2i NodeParams::get_int2(const std::string& n) const {
    const auto& v = std::get<std::vector<double>>(checked(n, ParamType::Int2, ParamType::Int2));
    return {{int(v[0]), int(v[1])}};
}
Vec3i NodeParams::get_int3(const std::string& n) const {
    const auto& v = std::get<std::vector<double>>(checked(n, ParamType::Int3, ParamType::Int3));
    return {{int(v[0]), int(v[1]), int(v[2])}};
}
std::filesystem::path NodeParams::get_path(const std::string& n) const {
    const std::string& s = std::get<std::string>(checked(n, ParamType::Path, ParamType::Path));
    std::filesystem::path p(s);
    if (s.empty() || p.is_absolute()) return p;
    return (base_dir_ / p).lexically_normal();
}

// ---------------------------------------------------------------- CookContext

CookContext::CookContext(std::string node_name, std::string node_type, const NodeDeclaration& decl, const NodeParams& params,
                         std::map<std::string, Value> inputs, const MemoryBudget& budget, const ProgressSink& progress)
    : name_(std::move(node_name)), type_(std::move(node_type)), decl_(decl), params_(params), inputs_(std::move(inputs)),
      budget_(budget), progress_(progress) {}

bool CookContext::has_input(const std::string& port) const {
    auto it = inputs_.find(port);
    return it != inputs_.end() && it->second.index() != 0;
}

const Value& CookContext::input(const std::string& port) const {
    if (!decl_.find_input(port)) throw Error("internal: node '" + name_ + "' reads undeclared input '" + port + "'");
    auto it = inputs_.find(port);
    if (it == inputs_.end() || it->second.index() == 0) fail("input '" + port + "' is not connected");
    return it->second;
}

namespace {
template <typename Ptr>
Ptr typed_input(const CookContext& ctx, const std::string& port, PortType want) {
    const Value& v = ctx.input(port);
    if (const Ptr* p = std::get_if<Ptr>(&v)) return *p;
    ctx.fail("input '" + port + "' expects a " + std::string(port_type_name(want)) + ", got a " +
             std::string(port_type_name(value_type(v))));
}
} // namespace

Field2DPtr CookContext::input_field2d(const std::string& port) const { return typed_input<Field2DPtr>(*this, port, PortType::Field2D); }
Field3DPtr CookContext::input_field3d(const std::string& port) const { return typed_input<Field3DPtr>(*this, port, PortType::Field3D); }
MeshPtr CookContext::input_mesh(const std::string& port) const { return typed_input<MeshPtr>(*this, port, PortType::Mesh); }
PointsPtr CookContext::input_points(const std::string& port) const { return typed_input<PointsPtr>(*this, port, PortType::Points); }

void CookContext::set_output(const std::string& port, Value v) {
    const PortDecl* p = decl_.find_output(port);
    if (!p) throw Error("internal: node '" + name_ + "' sets undeclared output '" + port + "'");
    if (v.index() == 0) throw Error("internal: node '" + name_ + "' sets an empty value on '" + port + "'");
    if (!port_accepts(p->type, value_type(v)))
        throw Error("internal: node '" + name_ + "' output '" + port + "' is declared " + std::string(port_type_name(p->type)) +
                    " but was given a " + std::string(port_type_name(value_type(v))));
    outputs_[port] = std::move(v);
}

// Creates a field, naming this node in budget and shape errors.
template <typename F, typename Res, typename Box>
std::shared_ptr<F> make_named_field(const CookContext& ctx, const MemoryBudget& budget, Res res, int channels, Box bounds,
                                    std::vector<std::string> names) {
    try {
        // Held against the budget for as long as the field lives (a scratch
        // field until the node drops it, an output while a value or the
        // cache keeps it).
        auto* raw = new F(res, channels, bounds, std::move(names), &budget);
        std::shared_ptr<void> token = detail::hold_against(budget, raw, raw->byte_size());
        return std::shared_ptr<F>(raw, [token](F* p) mutable {
            delete p;
            token.reset();
        });
    } catch (const MemoryBudgetError& e) {
        throw MemoryBudgetError("node '" + ctx.node_name() + "': " + e.what());
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}

std::shared_ptr<Field2D> CookContext::make_field2d(Vec2i res, int channels, Box2d bounds, std::vector<std::string> names) const {
    return make_named_field<Field2D>(*this, budget_, res, channels, bounds, std::move(names));
}

std::shared_ptr<Field3D> CookContext::make_field3d(Vec3i res, int channels, Box3d bounds, std::vector<std::string> names) const {
    return make_named_field<Field3D>(*this, budget_, res, channels, bounds, std::move(names));
}

void CookContext::check_memory(uint64_t bytes, std::string_view what) const {
    budget_.check(bytes, "node '" + name_ + "': " + std::string(what));
}

void CookContext::progress(double fraction) const {
    progress_.poll();
    if (progress_.on_progress) progress_.on_progress({"node '" + name_ + "'", std::clamp(fraction, 0.0, 1.0), 0, 0});
}

GridFrame CookContext::frame(const Field3D& f) const {
    if (!window_) return f.frame();
    const Box2d& b = window_->grid.bounds;
    return {{{window_->grid.res[0], window_->grid.res[1], f.nz()}},
            {{{b.min[0], b.min[1], f.bounds().min[2]}}, {{b.max[0], b.max[1], f.bounds().max[2]}}},
            {{window_->x0, window_->y0, 0}}};
}

void CookContext::fail(const std::string& message) const { throw Error("node '" + name_ + "' (" + type_ + "): " + message); }

// ---------------------------------------------------------------- NodeRegistry

void NodeRegistry::add(NodeType type) {
    if (type.name.empty() || !type.cook || !type.declare) throw Error("internal: node type needs a name, declare() and cook()");
    if (types_.count(type.name)) throw Error("internal: node type '" + type.name + "' registered twice");
    type.decl = NodeDeclaration();
    type.declare(type.decl);
    std::string name = type.name;
    types_.emplace(std::move(name), std::move(type));
}

const NodeType* NodeRegistry::find(const std::string& name) const {
    auto it = types_.find(name);
    return it == types_.end() ? nullptr : &it->second;
}

std::vector<const NodeType*> NodeRegistry::all() const {
    std::vector<const NodeType*> v;
    for (const auto& kv : types_) v.push_back(&kv.second);
    return v;
}

std::vector<std::string> NodeRegistry::names() const {
    std::vector<std::string> v;
    for (const auto& kv : types_) v.push_back(kv.first);
    return v;
}

} // namespace atlas
