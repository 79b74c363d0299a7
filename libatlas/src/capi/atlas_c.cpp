// The C API (atlas/atlas.h) over atlas::Session. Every entry point catches
// everything: no exception crosses into C.
#include "atlas/atlas.h"

// This file is compiled with hidden visibility (only ATLAS_API is exported);
// the C++ API it uses keeps its default visibility, so that type information
// (atlas::Error) stays one and the same inside a shared libatlas.
#pragma GCC visibility push(default)
#include "atlas/graph/evaluator.h"
#pragma GCC visibility pop

#include <nlohmann/json.hpp>

#include <atomic>
#include <cmath>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <variant>

struct AtlasSession {
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

AtlasStatus atlas_session_create(AtlasSession** out) {
    if (!out) return ATLAS_INVALID_ARGUMENT;
    *out = nullptr;
    try {
        *out = new AtlasSession();
        return ATLAS_OK;
    } catch (const std::bad_alloc&) {
        return ATLAS_OUT_OF_MEMORY;
    } catch (...) {
        return ATLAS_ERROR;
    }
}

void atlas_session_destroy(AtlasSession* session) { delete session; }

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
