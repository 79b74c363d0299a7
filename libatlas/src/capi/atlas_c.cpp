// The C API (atlas/atlas.h) over atlas::Session. Every entry point catches
// everything: no exception crosses into C.
#include "atlas/atlas.h"
#include "atlas/preview/graph_preview.h"

// This file is compiled with hidden visibility (only ATLAS_API is exported);
// the C++ API it uses keeps its default visibility, so that type information
// (atlas::Error) stays one and the same inside a shared libatlas.
#pragma GCC visibility push(default)
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node_builder.h"
#pragma GCC visibility pop

#include <nlohmann/json.hpp>

#include <atomic>
#include <algorithm>
#include <cmath>
#include <deque>
#include <exception>
#include <map>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <variant>
#include <chrono>
#include <thread>

struct AtlasSession {
    AtlasSession() = default;
    explicit AtlasSession(atlas::NodeRegistry registry) : session(std::move(registry)) {}
    atlas::Session session{atlas::builtin_nodes()};
    std::atomic<bool> busy{false}; // a call is running (ATLAS_BUSY for a second thread)
    std::string error;
    atlas::SourceLocation error_where;
    atlas::CookResult last;
    bool has_last = false;
    std::string report_json;
    std::string node_types_json;
};

struct AtlasField {
    atlas::Field2DPtr f2;
    atlas::Field3DPtr f3;
    const atlas::detail::FieldStorage& storage() const {
        if (f3) return *f3;
        return *f2;
    }
};

struct AtlasMesh {
    atlas::MeshPtr m;
};

struct AtlasPoints {
    atlas::PointsPtr p;
};

namespace {

// A caller's mistake (NULL argument, a value that is not a field): ATLAS_INVALID_ARGUMENT.
struct InvalidArgument : std::runtime_error {
    using std::runtime_error::runtime_error;
};

AtlasStatus fail(AtlasSession* s, AtlasStatus status, std::string message) {
    s->error = std::move(message);
    return status;
}

// Runs `body` on the session, mapping every exception to a status and a message.
template <typename Body>
AtlasStatus guarded(AtlasSession* s, Body&& body) {
    if (!s) return ATLAS_INVALID_ARGUMENT;
    // Another thread is inside a call on this session: touch nothing (not even the message).
    if (s->busy.exchange(true)) return ATLAS_BUSY;
    struct Release {
        std::atomic<bool>& b;
        ~Release() { b = false; }
    } release{s->busy};
    s->error.clear();
    s->error_where = {};
    try {
        body();
        return ATLAS_OK;
    } catch (const atlas::ParseError& e) {
        s->error_where = e.where();
        return fail(s, ATLAS_PARSE_ERROR, e.what());
    } catch (const InvalidArgument& e) {
        return fail(s, ATLAS_INVALID_ARGUMENT, e.what());
    } catch (const atlas::CancelledError& e) {
        return fail(s, ATLAS_CANCELLED, e.what());
    } catch (const atlas::MemoryBudgetError& e) {
        return fail(s, ATLAS_OUT_OF_MEMORY, e.what());
    } catch (const std::bad_alloc&) {
        return fail(s, ATLAS_OUT_OF_MEMORY, "out of memory");
    } catch (const std::exception& e) {
        return fail(s, ATLAS_ERROR, e.what());
    } catch (...) {
        return fail(s, ATLAS_ERROR, "unknown error");
    }
}

// A typed value for NODE.PARAM, converted to the declared type where that
// loses nothing (an int for a float parameter, an integral float for an int).
atlas::ParamValue coerce(const atlas::Session& session, const char* node, const char* param, atlas::ParamValue v) {
    const atlas::GraphNode* n = session.graph().find(node);
    if (!n) return v;
    const atlas::NodeType* type = session.registry().find(n->type);
    const atlas::ParamDecl* decl = type ? type->decl.find_param(param) : nullptr;
    if (!decl) return v;
    if (decl->type == atlas::ParamType::Float) {
        if (auto* i = std::get_if<int64_t>(&v)) return static_cast<double>(*i);
    } else if (decl->type == atlas::ParamType::Int) {
        if (auto* d = std::get_if<double>(&v); d && std::isfinite(*d) && std::floor(*d) == *d && std::fabs(*d) < 9.0e15)
            return static_cast<int64_t>(*d);
    }
    return v;
}

atlas::CookOptions cook_options(const AtlasCookOptions* o) {
    atlas::CookOptions opt;
    opt.write_outputs = false;
    if (!o) return opt;
    // Members a caller's (older, smaller) struct does not have keep their defaults.
    auto has = [&](size_t end_offset) { return o->struct_size >= end_offset; };
    if (has(offsetof(AtlasCookOptions, jobs) + sizeof(int))) opt.jobs = o->jobs;
    if (has(offsetof(AtlasCookOptions, write_outputs) + sizeof(int))) opt.write_outputs = o->write_outputs != 0;
    if (has(offsetof(AtlasCookOptions, out_dir) + sizeof(char*)) && o->out_dir) opt.out_dir = o->out_dir;
    if (has(offsetof(AtlasCookOptions, cache_dir) + sizeof(char*)) && o->cache_dir && *o->cache_dir)
        opt.cache_dir = std::filesystem::path(o->cache_dir);
    if (has(offsetof(AtlasCookOptions, memory_budget) + sizeof(uint64_t)) && o->memory_budget)
        opt.memory_budget = o->memory_budget;
    if (has(offsetof(AtlasCookOptions, proxy) + sizeof(int)) && o->proxy > 1) opt.proxy = o->proxy;
    if (has(offsetof(AtlasCookOptions, user) + sizeof(void*))) {
        void* user = o->user;
        if (AtlasProgressFn fn = o->progress)
            opt.progress.on_progress = [fn, user](const atlas::ProgressEvent& e) {
                fn(user, e.task.c_str(), e.fraction, e.done, e.total);
            };
        if (AtlasCancelFn fn = o->cancel) opt.progress.is_cancelled = [fn, user] { return fn(user) != 0; };
    }
    return opt;
}

nlohmann::json param_json(const atlas::ParamValue& v) {
    return std::visit([](const auto& x) { return nlohmann::json(x); }, v);
}

std::string node_types_json(const atlas::NodeRegistry& registry) {
    nlohmann::json types = nlohmann::json::array();
    auto ports = [](const auto& list) {
        nlohmann::json a = nlohmann::json::array();
        for (const atlas::PortDecl& p : list)
            a.push_back({{"name", p.name}, {"type", std::string(atlas::port_type_name(p.type))}, {"doc", p.doc},
                         {"optional", p.optional}});
        return a;
    };
    for (const atlas::NodeType* t : registry.all()) {
        nlohmann::json params = nlohmann::json::array();
        for (const atlas::ParamDecl& p : t->decl.params()) {
            nlohmann::json j = {{"name", p.name}, {"type", std::string(atlas::param_type_name(p.type))},
                                {"default", param_json(p.default_value)}, {"unit", p.unit}, {"doc", p.doc},
                                {"min", nullptr}, {"max", nullptr}, {"choices", p.choices}};
            if (p.min) j["min"] = *p.min;
            if (p.max) j["max"] = *p.max;
            params.push_back(std::move(j));
        }
        types.push_back({{"name", t->name}, {"version", t->version}, {"doc", t->decl.doc()},
                         {"inputs", ports(t->decl.inputs())}, {"outputs", ports(t->decl.outputs())},
                         {"params", std::move(params)}});
    }
    return types.dump();
}

// Cooks what NODE.PORT needs (PORT empty: the node's first output) and checks the kind of value.
atlas::Value get_value(AtlasSession* s, const char* node, const char* port, const AtlasCookOptions* options,
                       const char* expected, bool (*is_expected)(const atlas::Value&)) {
    std::string port_name = port ? port : "";
    if (port_name.empty()) {
        const atlas::GraphNode* n = s->session.graph().find(node);
        const atlas::NodeType* t = n ? s->session.registry().find(n->type) : nullptr;
        if (t && !t->decl.outputs().empty()) port_name = t->decl.outputs().front().name;
    }
    s->has_last = false;
    atlas::Value v = s->session.get(node, port_name, cook_options(options));
    if (!is_expected(v))
        throw InvalidArgument("node '" + std::string(node) + "' port '" + port_name + "' is a " +
                              (v.index() == 0 ? std::string("empty value")
                                              : std::string(atlas::port_type_name(atlas::value_type(v)))) +
                              ", not " + expected);
    return v;
}


// Creates a handle: no exception crosses into C (a failed allocation is a status).
template <class T, class... Args>
AtlasStatus create_handle(T** out, const Args&... args) {
    if (!out) return ATLAS_INVALID_ARGUMENT;
    *out = nullptr;
    try {
        *out = new T(args...);
        return ATLAS_OK;
    } catch (const std::bad_alloc&) {
        return ATLAS_OUT_OF_MEMORY;
    } catch (...) {
        return ATLAS_ERROR;
    }
}

} // namespace

extern "C" {

const char* atlas_status_name(AtlasStatus status) {
    switch (status) {
    case ATLAS_OK: return "ok";
    case ATLAS_ERROR: return "error";
    case ATLAS_PARSE_ERROR: return "parse error";
    case ATLAS_INVALID_ARGUMENT: return "invalid argument";
    case ATLAS_CANCELLED: return "cancelled";
    case ATLAS_OUT_OF_MEMORY: return "out of memory";
    case ATLAS_BUSY: return "busy";
    }
    return "unknown status";
}

const char* atlas_version(void) { return ATLAS_VERSION_STRING; }

AtlasStatus atlas_session_create(AtlasSession** out) { return create_handle(out); }

void atlas_session_destroy(AtlasSession* session) {
    if (!session) return;
    // A call running on another thread still uses the session: wait for it to
    // return (a host cancels it through its progress callback to make that quick).
    while (session->busy.exchange(true)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    delete session;
}

const char* atlas_session_error(const AtlasSession* session) { return session ? session->error.c_str() : "no session"; }

void atlas_session_error_location(const AtlasSession* session, const char** file, int* line, int* column) {
    static const char* const empty = "";
    if (file) *file = session ? session->error_where.file.c_str() : empty;
    if (line) *line = session ? session->error_where.line : 0;
    if (column) *column = session ? session->error_where.column : 0;
}

AtlasStatus atlas_session_load(AtlasSession* s, const char* graph_path) {
    return guarded(s, [&] {
        if (!graph_path) throw InvalidArgument("atlas_session_load: graph_path is NULL");
        s->session.load(graph_path);
    });
}

AtlasStatus atlas_session_load_text(AtlasSession* s, const char* yaml, const char* name, const char* base_dir) {
    return guarded(s, [&] {
        if (!yaml) throw InvalidArgument("atlas_session_load_text: yaml is NULL");
        s->session.load_text(yaml, name ? name : "<text>",
                             base_dir ? std::filesystem::path(base_dir) : std::filesystem::current_path());
    });
}

AtlasStatus atlas_session_set(AtlasSession* s, const char* node, const char* param, const char* value_text) {
    return guarded(s, [&] {
        if (!node || !param || !value_text) throw InvalidArgument("atlas_session_set: NULL argument");
        s->session.set_text(node, param, value_text);
    });
}

AtlasStatus atlas_session_set_time(AtlasSession* s, double t) {
    return guarded(s, [&] {
        if (!std::isfinite(t)) throw InvalidArgument("atlas_session_set_time: the time must be finite");
        s->session.set_time(t);
    });
}

AtlasStatus atlas_session_set_float(AtlasSession* s, const char* node, const char* param, double value) {
    return guarded(s, [&] {
        if (!node || !param) throw InvalidArgument("atlas_session_set_float: NULL argument");
        s->session.set(node, param, coerce(s->session, node, param, value));
    });
}

AtlasStatus atlas_session_set_int(AtlasSession* s, const char* node, const char* param, int64_t value) {
    return guarded(s, [&] {
        if (!node || !param) throw InvalidArgument("atlas_session_set_int: NULL argument");
        s->session.set(node, param, coerce(s->session, node, param, value));
    });
}

AtlasStatus atlas_session_set_bool(AtlasSession* s, const char* node, const char* param, int value) {
    return guarded(s, [&] {
        if (!node || !param) throw InvalidArgument("atlas_session_set_bool: NULL argument");
        s->session.set(node, param, atlas::ParamValue(value != 0));
    });
}

void atlas_cook_options_init(AtlasCookOptions* options) {
    if (!options) return;
    *options = AtlasCookOptions{};
    options->struct_size = sizeof(AtlasCookOptions);
}

AtlasStatus atlas_session_cook(AtlasSession* s, const AtlasCookOptions* options) {
    return guarded(s, [&] {
        s->has_last = false;
        s->last = s->session.cook(cook_options(options));
        s->has_last = true;
    });
}


AtlasStatus atlas_session_get(AtlasSession* s, const char* node, const char* port, const AtlasCookOptions* options,
                              AtlasField** out) {
    if (out) *out = nullptr;
    return guarded(s, [&] {
        if (!node || !out) throw InvalidArgument("atlas_session_get: NULL argument");
        atlas::Value v = get_value(s, node, port, options, "a field", [](const atlas::Value& x) {
            return std::holds_alternative<atlas::Field3DPtr>(x) || std::holds_alternative<atlas::Field2DPtr>(x);
        });
        auto f = std::make_unique<AtlasField>();
        if (auto* p3 = std::get_if<atlas::Field3DPtr>(&v)) f->f3 = *p3;
        else f->f2 = std::get<atlas::Field2DPtr>(v);
        *out = f.release();
    });
}

AtlasStatus atlas_session_preview(AtlasSession* s, const char* options_json, const AtlasCookOptions* options, AtlasField** out) {
    if (out) *out = nullptr;
    return guarded(s, [&] {
        if (!out) throw InvalidArgument("atlas_session_preview: NULL argument");
        atlas::preview::GraphPreviewOptions how;
        const atlas::CookOptions co = cook_options(options);
        how.jobs = co.jobs;
        how.cache_dir = co.cache_dir;
        how.progress = co.progress;
        how.proxy = co.proxy;
        std::vector<std::pair<std::string, std::string>> settings;
        if (options_json && *options_json) {
            nlohmann::json j;
            try {
                j = nlohmann::json::parse(options_json);
            } catch (const nlohmann::json::exception& e) {
                throw InvalidArgument(std::string("atlas_session_preview: options_json is not JSON: ") + e.what());
            }
            if (!j.is_object()) throw InvalidArgument("atlas_session_preview: options_json must be a JSON object of preview options");
            for (const auto& [name, v] : j.items()) {
                std::string text;
                if (v.is_string()) text = v.get<std::string>();
                else if (v.is_array()) {
                    for (const auto& x : v) text += (text.empty() ? "" : ",") + (x.is_string() ? x.get<std::string>() : x.dump());
                } else text = v.dump();
                if (name == "mode") how.mode = text;
                else if (name == "noise") how.noise = text;
                else settings.emplace_back(name, text);
            }
        }
        atlas::render::PreviewOptions po;
        atlas::preview::set_preview_options(po, settings);
        atlas::render::PreviewFrame f = atlas::preview::preview_session(s->session, po, how);
        auto field = std::make_unique<AtlasField>();
        field->f2 = std::make_shared<const atlas::Field2D>(std::move(f.image));
        *out = field.release();
    });
}

AtlasStatus atlas_session_get_mesh(AtlasSession* s, const char* node, const char* port, const AtlasCookOptions* options,
                                   AtlasMesh** out) {
    if (out) *out = nullptr;
    return guarded(s, [&] {
        if (!node || !out) throw InvalidArgument("atlas_session_get_mesh: NULL argument");
        atlas::Value v = get_value(s, node, port, options, "a mesh",
                                   [](const atlas::Value& x) { return std::holds_alternative<atlas::MeshPtr>(x); });
        *out = new AtlasMesh{std::get<atlas::MeshPtr>(v)};
    });
}

AtlasStatus atlas_session_get_points(AtlasSession* s, const char* node, const char* port,
                                     const AtlasCookOptions* options, AtlasPoints** out) {
    if (out) *out = nullptr;
    return guarded(s, [&] {
        if (!node || !out) throw InvalidArgument("atlas_session_get_points: NULL argument");
        atlas::Value v = get_value(s, node, port, options, "points",
                                   [](const atlas::Value& x) { return std::holds_alternative<atlas::PointsPtr>(x); });
        *out = new AtlasPoints{std::get<atlas::PointsPtr>(v)};
    });
}

void atlas_mesh_release(AtlasMesh* mesh) { delete mesh; }
size_t atlas_mesh_vertex_count(const AtlasMesh* m) { return m ? m->m->vertices.size() : 0; }
const float* atlas_mesh_vertices(const AtlasMesh* m) {
    static_assert(sizeof(atlas::Vec3f) == 3 * sizeof(float), "vertices are read as packed floats");
    return m && !m->m->vertices.empty() ? &m->m->vertices[0][0] : nullptr;
}
size_t atlas_mesh_triangle_count(const AtlasMesh* m) { return m ? m->m->triangles.size() : 0; }
const uint32_t* atlas_mesh_triangles(const AtlasMesh* m) {
    return m && !m->m->triangles.empty() ? m->m->triangles[0].data() : nullptr;
}

void atlas_points_release(AtlasPoints* points) { delete points; }
size_t atlas_points_count(const AtlasPoints* p) { return p ? p->p->positions.size() : 0; }
const float* atlas_points_positions(const AtlasPoints* p) {
    return p && !p->p->positions.empty() ? &p->p->positions[0][0] : nullptr;
}
int atlas_points_attribute_count(const AtlasPoints* p) { return p ? int(p->p->attributes.size()) : 0; }
const char* atlas_points_attribute_name(const AtlasPoints* p, int index) {
    if (!p || index < 0 || index >= int(p->p->attributes.size())) return nullptr;
    auto it = p->p->attributes.begin();
    std::advance(it, index);
    return it->first.c_str();
}
const float* atlas_points_attribute(const AtlasPoints* p, const char* name) {
    if (!p || !name) return nullptr;
    auto it = p->p->attributes.find(name);
    return it == p->p->attributes.end() || it->second.empty() ? nullptr : it->second.data();
}

const char* atlas_session_node_status(const AtlasSession* s, const char* node) {
    if (!s || !node || !s->has_last) return nullptr;
    auto it = s->last.nodes.find(node);
    return it == s->last.nodes.end() ? nullptr : it->second.status.c_str();
}

const char* atlas_session_report_json(AtlasSession* s) {
    if (!s) return nullptr;
    try {
        s->report_json = s->has_last ? s->last.to_json(s->session.graph().file.string()) : "{}";
    } catch (...) {
        s->report_json = "{}";
    }
    return s->report_json.c_str();
}

const char* atlas_session_node_types_json(AtlasSession* s) {
    if (!s) return nullptr;
    try {
        if (s->node_types_json.empty()) s->node_types_json = node_types_json(s->session.registry());
        return s->node_types_json.c_str();
    } catch (...) {
        return nullptr;
    }
}

void atlas_field_release(AtlasField* field) { delete field; }

int atlas_field_dimensions(const AtlasField* f) { return !f ? 0 : f->f3 ? 3 : 2; }

void atlas_field_resolution(const AtlasField* f, int resolution[3]) {
    if (!resolution) return;
    resolution[0] = resolution[1] = resolution[2] = 0;
    if (!f) return;
    if (f->f3) {
        for (int i = 0; i < 3; ++i) resolution[i] = f->f3->resolution()[i];
    } else {
        resolution[0] = f->f2->width();
        resolution[1] = f->f2->height();
        resolution[2] = 1;
    }
}

void atlas_field_bounds(const AtlasField* f, double min[3], double max[3]) {
    if (!min || !max) return;
    for (int i = 0; i < 3; ++i) min[i] = max[i] = 0;
    if (!f) return;
    if (f->f3) {
        for (int i = 0; i < 3; ++i) {
            min[i] = f->f3->bounds().min[i];
            max[i] = f->f3->bounds().max[i];
        }
    } else {
        for (int i = 0; i < 2; ++i) {
            min[i] = f->f2->bounds().min[i];
            max[i] = f->f2->bounds().max[i];
        }
    }
}

int atlas_field_channels(const AtlasField* f) { return f ? f->storage().channels() : 0; }

const char* atlas_field_channel_name(const AtlasField* f, int channel) {
    if (!f || channel < 0 || channel >= f->storage().channels()) return nullptr;
    return f->storage().channel_name(channel).c_str();
}

size_t atlas_field_voxel_count(const AtlasField* f) { return f ? f->storage().voxel_count() : 0; }

const float* atlas_field_channel_data(const AtlasField* f, int channel) {
    if (!f || channel < 0 || channel >= f->storage().channels()) return nullptr;
    return f->storage().channel(channel).data();
}

} // extern "C"

// ------------------------------------------------------------------ node types written in C

struct AtlasRegistry {
    atlas::NodeRegistry registry = atlas::builtin_nodes();
    std::string error;
};

struct AtlasFieldBuilder {
    std::shared_ptr<atlas::Field2D> f2;
    std::shared_ptr<atlas::Field3D> f3;
    atlas::detail::FieldStorage& storage() {
        if (f3) return *f3;
        return *f2;
    }
};

struct AtlasCookContext {
    atlas::CookContext* ctx = nullptr;
    const atlas::NodeDeclaration* decl = nullptr;
    std::exception_ptr failure;                  // the first error; rethrown when the cook function returns
    std::map<std::string, std::unique_ptr<AtlasField>> inputs;
    std::vector<std::unique_ptr<AtlasFieldBuilder>> builders;
    std::deque<std::string> strings;             // string parameters handed out
    void fail_with(std::exception_ptr e) {
        if (!failure) failure = e;
    }
};

namespace {

// A JSON default as the ParamValue of type t; `what` names it in the message.
atlas::ParamValue param_from_json(const nlohmann::json& j, atlas::ParamType t, const std::string& what) {
    using T = atlas::ParamType;
    auto bad = [&](const char* expected) { return InvalidArgument(what + ": expected " + expected + ", got " + j.dump()); };
    switch (t) {
    case T::Float:
        if (!j.is_number()) throw bad("a number");
        return j.get<double>();
    case T::Int:
        if (!j.is_number_integer()) throw bad("an integer");
        return j.get<int64_t>();
    case T::Bool:
        if (!j.is_boolean()) throw bad("true or false");
        return j.get<bool>();
    case T::String:
    case T::Enum:
    case T::Path:
        if (!j.is_string()) throw bad("a string");
        return j.get<std::string>();
    default: {
        const size_t n = size_t(atlas::param_components(t));
        if (!j.is_array() || j.size() != n) throw bad(n == 2 ? "2 numbers" : "3 numbers");
        std::vector<double> v;
        for (const auto& x : j) {
            if (!x.is_number()) throw bad("numbers");
            v.push_back(x.get<double>());
        }
        return v;
    }
    }
}

// The declaration, read from JSON once, at registration: the JSON values become the
// library builder's plain data (atlas/graph/node_builder.h), which checks them as it
// checks Python's add_python_node.
atlas::NodeDeclarationBuilder parse_declaration(const nlohmann::json& j, const std::string& node) {
    atlas::NodeDeclarationBuilder d(node, j.value("doc", ""));
    auto ports = [&](const char* key, bool inputs) {
        if (!j.contains(key)) return;
        for (const auto& p : j.at(key)) {
            if (!p.contains("name")) throw InvalidArgument(node + ": a port needs a \"name\"");
            atlas::PortDecl port{p.at("name").get<std::string>(), atlas::port_type_named(p.value("type", "field")), p.value("doc", ""),
                                 p.value("optional", false)};
            if (inputs) d.input(std::move(port));
            else d.output(std::move(port));
        }
    };
    ports("inputs", true);
    ports("outputs", false);
    d.check_ports();
    if (j.contains("params")) {
        for (const auto& p : j.at("params")) {
            if (!p.contains("name") || !p.contains("type") || !p.contains("default"))
                throw InvalidArgument(node + ": a parameter needs \"name\", \"type\" and \"default\"");
            atlas::ParamDecl pd;
            pd.name = p.at("name").get<std::string>();
            pd.type = atlas::param_type_named(p.at("type").get<std::string>());
            pd.default_value = param_from_json(p.at("default"), pd.type, node + "." + pd.name + " default");
            if (p.contains("min") && !p.at("min").is_null()) pd.min = p.at("min").get<double>();
            if (p.contains("max") && !p.at("max").is_null()) pd.max = p.at("max").get<double>();
            pd.unit = p.value("unit", "");
            pd.doc = p.value("doc", "");
            if (p.contains("choices")) pd.choices = p.at("choices").get<std::vector<std::string>>();
            d.param(std::move(pd));
        }
    }
    return d;
}

// Runs `body` for an atlas_cook_* call: an exception becomes the node's failure.
template <typename Body>
AtlasStatus in_cook(AtlasCookContext* c, Body&& body) {
    if (!c || !c->ctx) return ATLAS_INVALID_ARGUMENT;
    try {
        body();
        return ATLAS_OK;
    } catch (const InvalidArgument&) {
        return ATLAS_INVALID_ARGUMENT; // the caller's mistake: a status, the cook may go on
    } catch (...) {
        c->fail_with(std::current_exception());
        return ATLAS_ERROR;
    }
}

const atlas::ParamValue& param_of(const AtlasCookContext* c, const char* name, atlas::ParamType a, atlas::ParamType b) {
    if (!name) throw InvalidArgument("NULL name");
    const atlas::ParamDecl* d = c->decl->find_param(name);
    if (!d || (d->type != a && d->type != b)) throw InvalidArgument("no such parameter of that type");
    return c->ctx->params().get(name);
}

} // namespace

extern "C" {

AtlasStatus atlas_registry_create(AtlasRegistry** out) { return create_handle(out); }

void atlas_registry_destroy(AtlasRegistry* registry) { delete registry; }

const char* atlas_registry_error(const AtlasRegistry* registry) { return registry ? registry->error.c_str() : "no registry"; }

AtlasStatus atlas_registry_add_node(AtlasRegistry* r, const char* declaration_json, AtlasNodeCookFn cook, void* user) {
    if (!r) return ATLAS_INVALID_ARGUMENT;
    r->error.clear();
    try {
        if (!declaration_json || !cook) throw InvalidArgument("atlas_registry_add_node: NULL argument");
        nlohmann::json j;
        try {
            j = nlohmann::json::parse(declaration_json);
        } catch (const nlohmann::json::exception& e) {
            throw InvalidArgument(std::string("declaration: ") + e.what());
        }
        if (!j.is_object() || !j.contains("name") || !j.at("name").is_string())
            throw InvalidArgument("declaration: an object with a \"name\" string");
        const std::string name = j.at("name").get<std::string>();
        auto parsed = std::make_shared<const atlas::NodeDeclarationBuilder>(parse_declaration(j, name));
        auto built = std::make_shared<atlas::NodeDeclaration>();
        parsed->declare(*built);
        atlas::NodeType t;
        t.name = name;
        t.version = j.value("version", 1);
        t.declare = [parsed](atlas::NodeDeclaration& d) { parsed->declare(d); };
        t.cook = [cook, user, built](atlas::CookContext& ctx) {
            AtlasCookContext c;
            c.ctx = &ctx;
            c.decl = built.get();
            const int rc = cook(user, &c);
            c.ctx = nullptr; // a context kept past the call is refused
            if (c.failure) std::rethrow_exception(c.failure);
            if (rc != 0) throw atlas::Error("the cook function returned " + std::to_string(rc));
            for (const atlas::PortDecl& out : built->outputs())
                if (!ctx.outputs().count(out.name)) throw atlas::Error("the cook function did not set output '" + out.name + "'");
        };
        r->registry.add(std::move(t));
        return ATLAS_OK;
    } catch (const InvalidArgument& e) {
        r->error = e.what();
        return ATLAS_INVALID_ARGUMENT;
    } catch (const atlas::DeclarationError& e) {
        r->error = e.what();
        return ATLAS_INVALID_ARGUMENT;
    } catch (const nlohmann::json::exception& e) {
        r->error = std::string("declaration: ") + e.what();
        return ATLAS_INVALID_ARGUMENT;
    } catch (const std::exception& e) {
        r->error = e.what();
        return ATLAS_ERROR;
    }
}

AtlasStatus atlas_session_create_with_registry(const AtlasRegistry* registry, AtlasSession** out) {
    if (out) *out = nullptr;
    if (!registry) return ATLAS_INVALID_ARGUMENT;
    return create_handle(out, registry->registry);
}

const char* atlas_cook_node_name(const AtlasCookContext* c) { return c && c->ctx ? c->ctx->node_name().c_str() : ""; }

AtlasStatus atlas_cook_param_float(const AtlasCookContext* c, const char* name, double* value) {
    return in_cook(const_cast<AtlasCookContext*>(c), [&] {
        if (!value) throw InvalidArgument("NULL value");
        *value = std::get<double>(param_of(c, name, atlas::ParamType::Float, atlas::ParamType::Float));
    });
}

AtlasStatus atlas_cook_param_int(const AtlasCookContext* c, const char* name, int64_t* value) {
    return in_cook(const_cast<AtlasCookContext*>(c), [&] {
        if (!value) throw InvalidArgument("NULL value");
        *value = std::get<int64_t>(param_of(c, name, atlas::ParamType::Int, atlas::ParamType::Int));
    });
}

AtlasStatus atlas_cook_param_bool(const AtlasCookContext* c, const char* name, int* value) {
    return in_cook(const_cast<AtlasCookContext*>(c), [&] {
        if (!value) throw InvalidArgument("NULL value");
        *value = std::get<bool>(param_of(c, name, atlas::ParamType::Bool, atlas::ParamType::Bool)) ? 1 : 0;
    });
}

AtlasStatus atlas_cook_param_string(const AtlasCookContext* c, const char* name, const char** value) {
    auto* m = const_cast<AtlasCookContext*>(c);
    return in_cook(m, [&] {
        if (!value || !name) throw InvalidArgument("NULL argument");
        const atlas::ParamDecl* d = c->decl->find_param(name);
        if (d && d->type == atlas::ParamType::Path) {
            m->strings.push_back(c->ctx->get_path(name).string()); // resolved against the graph file
        } else {
            m->strings.push_back(std::get<std::string>(param_of(c, name, atlas::ParamType::String, atlas::ParamType::Enum)));
        }
        *value = m->strings.back().c_str();
    });
}

AtlasStatus atlas_cook_param_vector(const AtlasCookContext* c, const char* name, double values[3], int* n) {
    return in_cook(const_cast<AtlasCookContext*>(c), [&] {
        if (!values || !n || !name) throw InvalidArgument("NULL argument");
        const atlas::ParamDecl* d = c->decl->find_param(name);
        if (!d || atlas::param_components(d->type) < 2) throw InvalidArgument("not a vector parameter");
        const auto& v = std::get<std::vector<double>>(c->ctx->params().get(name));
        *n = int(v.size());
        for (size_t i = 0; i < v.size() && i < 3; ++i) values[i] = v[i];
    });
}

const AtlasField* atlas_cook_input(AtlasCookContext* c, const char* port) {
    const AtlasField* result = nullptr;
    in_cook(c, [&] {
        if (!port) throw InvalidArgument("NULL port");
        if (!c->decl->find_input(port) || !c->ctx->has_input(port)) return;
        auto& slot = c->inputs[port];
        if (!slot) {
            const atlas::Value& v = c->ctx->input(port);
            auto f = std::make_unique<AtlasField>();
            if (auto* p3 = std::get_if<atlas::Field3DPtr>(&v)) f->f3 = *p3;
            else if (auto* p2 = std::get_if<atlas::Field2DPtr>(&v)) f->f2 = *p2;
            else return;
            slot = std::move(f);
        }
        result = slot.get();
    });
    return result;
}

AtlasFieldBuilder* atlas_cook_new_field(AtlasCookContext* c, int dimensions, const int resolution[3], int channels,
                                        const double min[3], const double max[3]) {
    AtlasFieldBuilder* result = nullptr;
    AtlasStatus st = in_cook(c, [&] {
        if (!resolution || !min || !max) throw atlas::Error("atlas_cook_new_field: NULL argument");
        auto b = std::make_unique<AtlasFieldBuilder>();
        if (dimensions == 3) {
            b->f3 = c->ctx->make_field3d(atlas::Vec3i{{resolution[0], resolution[1], resolution[2]}}, channels,
                                         atlas::Box3d{{{min[0], min[1], min[2]}}, {{max[0], max[1], max[2]}}});
        } else if (dimensions == 2) {
            b->f2 = c->ctx->make_field2d(atlas::Vec2i{{resolution[0], resolution[1]}}, channels,
                                         atlas::Box2d{{{min[0], min[1]}}, {{max[0], max[1]}}});
        } else {
            throw atlas::Error("atlas_cook_new_field: dimensions must be 2 or 3");
        }
        c->builders.push_back(std::move(b));
        result = c->builders.back().get();
    });
    return st == ATLAS_OK ? result : nullptr;
}

float* atlas_field_builder_channel(AtlasFieldBuilder* b, int channel) {
    if (!b || channel < 0 || channel >= b->storage().channels()) return nullptr;
    return b->storage().channel(channel).data();
}

AtlasStatus atlas_cook_set_output(AtlasCookContext* c, const char* port, AtlasFieldBuilder* b) {
    return in_cook(c, [&] {
        if (!port || !b) throw InvalidArgument("NULL argument");
        auto it = std::find_if(c->builders.begin(), c->builders.end(), [&](const auto& p) { return p.get() == b; });
        if (it == c->builders.end()) throw InvalidArgument("not a builder of this cook");
        const atlas::PortDecl* out = c->decl->find_output(port);
        if (!out) throw atlas::Error("no output port '" + std::string(port) + "'");
        atlas::Value v = b->f3 ? atlas::Value(atlas::Field3DPtr(b->f3)) : atlas::Value(atlas::Field2DPtr(b->f2));
        if (!atlas::port_accepts(out->type, atlas::value_type(v)))
            throw atlas::Error("output '" + std::string(port) + "' is a " + std::string(atlas::port_type_name(out->type)) +
                               ", got a " + std::string(atlas::port_type_name(atlas::value_type(v))));
        c->ctx->set_output(port, std::move(v));
        c->builders.erase(it);
    });
}

AtlasStatus atlas_cook_set_output_input(AtlasCookContext* c, const char* port, const char* input_port) {
    return in_cook(c, [&] {
        if (!port || !input_port) throw InvalidArgument("NULL argument");
        if (!c->decl->find_output(port)) throw atlas::Error("no output port '" + std::string(port) + "'");
        c->ctx->set_output(port, c->ctx->input(input_port));
    });
}

int atlas_cook_progress(AtlasCookContext* c, double fraction) {
    if (!c || !c->ctx) return 1;
    try {
        c->ctx->progress(fraction);
        return 0;
    } catch (...) {
        c->fail_with(std::current_exception()); // CancelledError: the cook ends as cancelled
        return 1;
    }
}

void atlas_cook_fail(AtlasCookContext* c, const char* message) {
    if (!c) return;
    c->fail_with(std::make_exception_ptr(atlas::Error(message && *message ? message : "the cook function failed")));
}

} // extern "C"
