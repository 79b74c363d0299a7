/* atlas/atlas.h - the C API: Atlas for hosts that are not C++ (Unity native
 * plugins and C#, Rust, Unreal's plugin boundary, Python through ctypes).
 *
 *   AtlasSession* s = NULL;
 *   atlas_session_create(&s);
 *   if (atlas_session_load(s, "clouds.yaml") != ATLAS_OK) puts(atlas_session_error(s));
 *   AtlasCookOptions o; atlas_cook_options_init(&o); o.jobs = 4;
 *   AtlasField* f = NULL;
 *   if (atlas_session_get(s, "coverage", "out", &o, &f) == ATLAS_OK) {
 *       const float* density = atlas_field_channel_data(f, 0);  ...
 *       atlas_field_release(f);
 *   }
 *   atlas_session_destroy(s);
 *
 * Rules for every function here:
 * - No C++ exception crosses this boundary: a failure is a status code, and
 *   the session keeps the message (atlas_session_error), which is the same
 *   text the CLI prints (file:line:col, node, parameter, what was expected).
 * - Handles are opaque. A session is not thread-safe: one call at a time per
 *   session (a call made while another thread is inside one returns
 *   ATLAS_BUSY and does nothing). Different sessions are independent and may
 *   be used from different threads at once. A field is immutable and may be read from any
 *   number of threads; it stays valid after its session is destroyed, until
 *   atlas_field_release.
 * - Strings returned by the library are owned by it: a session's strings stay
 *   valid until the next call on that session, a field's until its release.
 * - Strings passed in are UTF-8 and NUL-terminated; they are copied.
 * - The library never prints and never exits.
 *
 * This is the stable ABI across versions: functions are only added, and
 * AtlasCookOptions only grows at its end (its struct_size field says which
 * members a caller knows).
 *
 * Implemented in src/capi/atlas_c.cpp.
 */
#ifndef ATLAS_ATLAS_H
#define ATLAS_ATLAS_H

#include "atlas/export.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum AtlasStatus {
    ATLAS_OK = 0,
    ATLAS_ERROR = 1,            /* any other failure (an invalid graph, a node that failed, I/O) */
    ATLAS_PARSE_ERROR = 2,      /* a graph file or text that cannot be used: the error has a location */
    ATLAS_INVALID_ARGUMENT = 3, /* a NULL handle or string, a port that is not a field, no graph loaded */
    ATLAS_CANCELLED = 4,        /* the cancel callback asked to stop */
    ATLAS_OUT_OF_MEMORY = 5,    /* the memory budget (or the machine) refused an allocation */
    ATLAS_BUSY = 6              /* another thread is inside a call on this session: nothing was done,
                                   and atlas_session_error still describes that thread's calls */
} AtlasStatus;

/* "ok", "error", "parse error", "invalid argument", "cancelled", "out of memory", "busy". */
ATLAS_API const char* atlas_status_name(AtlasStatus status);
/* The library's version, "MAJOR.MINOR.PATCH". */
ATLAS_API const char* atlas_version(void);

typedef struct AtlasSession AtlasSession;
typedef struct AtlasField AtlasField;

/* A session over the built-in node types, with no graph loaded yet. */
ATLAS_API AtlasStatus atlas_session_create(AtlasSession** out);
/* Frees the session and its in-memory cache (NULL is allowed). Fields got
 * from it stay valid. A call running on the session in another thread is
 * waited for first (cancel it through its progress callback to make that
 * quick); the handle must not be used once this was called. */
ATLAS_API void atlas_session_destroy(AtlasSession* session);

/* The message of the last call on this session that failed, or "" when the
 * last call succeeded. */
ATLAS_API const char* atlas_session_error(const AtlasSession* session);
/* Where the last error is, when it is a parse error: the file (or the name
 * given to atlas_session_load_text) and the 1-based line and column; "" and
 * 0 otherwise. Any output pointer may be NULL. */
ATLAS_API void atlas_session_error_location(const AtlasSession* session, const char** file, int* line, int* column);

/* Loads (parses and validates) a graph file; replaces any loaded graph and
 * its parameter overrides. The in-memory cache is kept: reloading an edited
 * file re-cooks only what changed. */
ATLAS_API AtlasStatus atlas_session_load(AtlasSession* session, const char* graph_path);
/* The same from YAML text; `name` is used in messages (NULL: "<text>"),
 * relative paths resolve against `base_dir` (NULL: the current directory). */
ATLAS_API AtlasStatus atlas_session_load_text(AtlasSession* session, const char* yaml, const char* name,
                                              const char* base_dir);

/* Overrides NODE.PARAM, validated against the node's declaration (type,
 * range, choices). The text is spelled as in a graph file or the CLI's --set:
 * "0.5", "4", "true", "[1, 2, 3]", "name". */
ATLAS_API AtlasStatus atlas_session_set(AtlasSession* session, const char* node, const char* param,
                                        const char* value_text);
/* Sets the graph's time in seconds (docs/graph-format.md, "Time"): parameters
 * keyed over time take their values at t, and the next cook re-cooks only the
 * nodes that read them. ATLAS_INVALID_ARGUMENT for a time that is not finite. */
ATLAS_API AtlasStatus atlas_session_set_time(AtlasSession* session, double t);
/* Typed overrides: an integral value is accepted by a float parameter and a
 * float with an integral value by an int parameter. */
ATLAS_API AtlasStatus atlas_session_set_float(AtlasSession* session, const char* node, const char* param,
                                              double value);
ATLAS_API AtlasStatus atlas_session_set_int(AtlasSession* session, const char* node, const char* param,
                                            int64_t value);
ATLAS_API AtlasStatus atlas_session_set_bool(AtlasSession* session, const char* node, const char* param,
                                             int value);

/* Progress: a fraction 0..1 of the whole cook, with what is running ("node
 * 'coverage'") and nodes done/total. May be called from worker threads, also
 * concurrently: make it thread-safe. */
typedef void (*AtlasProgressFn)(void* user, const char* task, double fraction, int done, int total);
/* Cancellation: polled from worker threads during the cook; return nonzero to
 * stop. The cook then returns ATLAS_CANCELLED and writes nothing. */
typedef int (*AtlasCancelFn)(void* user);

typedef struct AtlasCookOptions {
    size_t struct_size;       /* sizeof(AtlasCookOptions), set by atlas_cook_options_init */
    int jobs;                 /* threads; 0 = all hardware threads. Results do not depend on it */
    int write_outputs;        /* nonzero: also write the graph's outputs into out_dir (atomically) */
    const char* out_dir;      /* NULL: the current directory */
    const char* cache_dir;    /* on-disk cache directory; NULL: memory cache only */
    uint64_t memory_budget;   /* bytes; 0: the default (8 GiB) */
    AtlasProgressFn progress; /* may be NULL */
    AtlasCancelFn cancel;     /* may be NULL */
    void* user;               /* passed to progress and cancel */
    int proxy;                /* 0 or 1: full resolution; P > 1: every world grid at 1/P of its cells
                                 per axis over the same bounds, for interaction (never written) */
} AtlasCookOptions;

/* Defaults: all threads, values only (no files written), no disk cache. */
ATLAS_API void atlas_cook_options_init(AtlasCookOptions* options);

/* Cooks every output of the graph (what they need, nothing else; what is
 * cached is not cooked again). `options` may be NULL (the defaults). */
ATLAS_API AtlasStatus atlas_session_cook(AtlasSession* session, const AtlasCookOptions* options);
/* Cooks what one node output needs and returns its value as a new field
 * handle (release it with atlas_field_release). `port` NULL or "" is the
 * node's first output. ATLAS_INVALID_ARGUMENT when the value is not a field
 * (a mesh or points). */
ATLAS_API AtlasStatus atlas_session_get(AtlasSession* session, const char* node, const char* port,
                                        const AtlasCookOptions* options, AtlasField** out);

/* What the last atlas_session_cook did with a node: "cooked", "cached" or
 * "skipped"; NULL when the node was not in it (or that cook failed, or the
 * last call was atlas_session_get). */
ATLAS_API const char* atlas_session_node_status(const AtlasSession* session, const char* node);
/* The last atlas_session_cook's report as JSON (the CLI's --report document,
 * docs/report.md); "{}" when there is none. */
ATLAS_API const char* atlas_session_report_json(AtlasSession* session);
/* Every node type's declaration as JSON: [{"name", "version", "doc", "inputs":
 * [{"name", "type", "doc", "optional"}], "outputs": [...], "params": [{"name",
 * "type", "default", "min", "max", "unit", "doc", "choices"}]}] - what a host
 * needs to draw parameter widgets. NULL on failure. */
ATLAS_API const char* atlas_session_node_types_json(AtlasSession* session);

/* Renders what the graph writes, as `atlas preview GRAPH` does, through the
 * session (values stay in memory: after an edit only the changed nodes cook;
 * nothing is written). `options_json`: NULL or a JSON object of preview options
 * by their docs/options.md names, as text or numbers ({"size": "640,360",
 * "view": "orbit", "sun_azimuth": 200}), plus "mode" (auto, voxel, layer) and
 * "noise" (auto, nubis, none, FILE). `options` (may be NULL) gives jobs, the
 * cache directory, proxy, progress and cancellation. The picture is a new 2D
 * field: channels r, g, b (linear radiance) and transmittance, one value per
 * pixel, row y = 0 at the bottom. */
ATLAS_API AtlasStatus atlas_session_preview(AtlasSession* session, const char* options_json, const AtlasCookOptions* options,
                                            AtlasField** out);

/* ------------------------------------------------------------------ fields
 * A field is a dense grid of float channels over a world box (metres),
 * cell-centred. Channel data is planar: channel c holds voxel_count floats,
 * x fastest, then y, then z. The functions below never fail on a valid
 * handle; on NULL or an out-of-range channel they return 0 / NULL. */
ATLAS_API void atlas_field_release(AtlasField* field);
/* 2 (an NDF, x and y) or 3 (a volume). */
ATLAS_API int atlas_field_dimensions(const AtlasField* field);
/* Voxels along x, y, z (z is 1 for a 2D field). */
ATLAS_API void atlas_field_resolution(const AtlasField* field, int resolution[3]);
/* World box in metres (z is 0..0 for a 2D field). */
ATLAS_API void atlas_field_bounds(const AtlasField* field, double min[3], double max[3]);
ATLAS_API int atlas_field_channels(const AtlasField* field);
ATLAS_API const char* atlas_field_channel_name(const AtlasField* field, int channel);
ATLAS_API size_t atlas_field_voxel_count(const AtlasField* field);
ATLAS_API const float* atlas_field_channel_data(const AtlasField* field, int channel);

/* ------------------------------------------------------------------ meshes and points
 * The values that are not fields: a triangle mesh and a point set with named
 * per-point float attributes (e.g. "radius"), coordinates in metres. Like
 * fields they are immutable, outlive their session and are released by the
 * host. atlas_session_get_mesh / _points return ATLAS_INVALID_ARGUMENT when
 * the port holds another kind of value. Accessors return 0 / NULL on NULL. */
typedef struct AtlasMesh AtlasMesh;
typedef struct AtlasPoints AtlasPoints;

ATLAS_API AtlasStatus atlas_session_get_mesh(AtlasSession* session, const char* node, const char* port,
                                             const AtlasCookOptions* options, AtlasMesh** out);
ATLAS_API void atlas_mesh_release(AtlasMesh* mesh);
ATLAS_API size_t atlas_mesh_vertex_count(const AtlasMesh* mesh);
/* x, y, z of each vertex: 3 * vertex_count floats. */
ATLAS_API const float* atlas_mesh_vertices(const AtlasMesh* mesh);
ATLAS_API size_t atlas_mesh_triangle_count(const AtlasMesh* mesh);
/* Three vertex indices per triangle: 3 * triangle_count values. */
ATLAS_API const uint32_t* atlas_mesh_triangles(const AtlasMesh* mesh);

ATLAS_API AtlasStatus atlas_session_get_points(AtlasSession* session, const char* node, const char* port,
                                               const AtlasCookOptions* options, AtlasPoints** out);
ATLAS_API void atlas_points_release(AtlasPoints* points);
ATLAS_API size_t atlas_points_count(const AtlasPoints* points);
/* x, y, z of each point: 3 * count floats. */
ATLAS_API const float* atlas_points_positions(const AtlasPoints* points);
/* Attributes in name order; atlas_points_attribute gives count floats, NULL for an unknown name. */
ATLAS_API int atlas_points_attribute_count(const AtlasPoints* points);
ATLAS_API const char* atlas_points_attribute_name(const AtlasPoints* points, int index);
ATLAS_API const float* atlas_points_attribute(const AtlasPoints* points, const char* name);

/* ------------------------------------------------------------------ node types written in C
 * A host adds node types to a registry and creates sessions over it. The
 * declaration is JSON in the shape atlas_session_node_types_json lists:
 *   {"name": "host/scale", "version": 1, "doc": "...",
 *    "inputs":  [{"name": "in", "type": "field3d", "doc": "...", "optional": false}],
 *    "outputs": [{"name": "out", "type": "field3d", "doc": "..."}],
 *    "params":  [{"name": "gain", "type": "float", "default": 2, "min": 0, "max": 10, "unit": "", "doc": "..."}]}
 * Such a node is validated, hashed (type, version, parameters, inputs) and
 * cached like a built-in one; Atlas cannot see into the cook function, so bump
 * "version" whenever it changes what it computes. */
typedef struct AtlasRegistry AtlasRegistry;
typedef struct AtlasCookContext AtlasCookContext;
typedef struct AtlasFieldBuilder AtlasFieldBuilder;

/* Cooks one node: reads parameters and inputs, sets every output. Returns 0 on
 * success; on failure call atlas_cook_fail (or return nonzero). Called from
 * worker threads, concurrently for different nodes. */
typedef int (*AtlasNodeCookFn)(void* user, AtlasCookContext* context);

/* A registry of the built-in node types. */
ATLAS_API AtlasStatus atlas_registry_create(AtlasRegistry** out);
ATLAS_API void atlas_registry_destroy(AtlasRegistry* registry);
/* Adds a node type; `user` is passed to every call of `cook`. On failure the
 * message is atlas_registry_error. */
ATLAS_API AtlasStatus atlas_registry_add_node(AtlasRegistry* registry, const char* declaration_json,
                                              AtlasNodeCookFn cook, void* user);
ATLAS_API const char* atlas_registry_error(const AtlasRegistry* registry);
/* A session over a copy of `registry` (later additions do not reach it). */
ATLAS_API AtlasStatus atlas_session_create_with_registry(const AtlasRegistry* registry, AtlasSession** out);

/* Inside a cook function (the context is valid only during that call). */
ATLAS_API const char* atlas_cook_node_name(const AtlasCookContext* context);
/* Resolved parameter values; ATLAS_INVALID_ARGUMENT for an undeclared name or another type.
 * A vector parameter fills values[0..n-1] (n = 2 or 3) and *n. A string's pointer lives
 * as long as the context. */
ATLAS_API AtlasStatus atlas_cook_param_float(const AtlasCookContext* context, const char* name, double* value);
ATLAS_API AtlasStatus atlas_cook_param_int(const AtlasCookContext* context, const char* name, int64_t* value);
ATLAS_API AtlasStatus atlas_cook_param_bool(const AtlasCookContext* context, const char* name, int* value);
ATLAS_API AtlasStatus atlas_cook_param_string(const AtlasCookContext* context, const char* name, const char** value);
ATLAS_API AtlasStatus atlas_cook_param_vector(const AtlasCookContext* context, const char* name, double values[3],
                                              int* n);
/* The field on an input port, borrowed for the call (do not release it); NULL
 * when the port is unconnected or holds no field. */
ATLAS_API const AtlasField* atlas_cook_input(AtlasCookContext* context, const char* port);
/* A new zero-filled field (dimensions 2: resolution[2] and z bounds are
 * ignored), checked against the memory budget; NULL on failure (the cook
 * then fails with the budget's message). Fill it, then atlas_cook_set_output. */
ATLAS_API AtlasFieldBuilder* atlas_cook_new_field(AtlasCookContext* context, int dimensions, const int resolution[3],
                                                  int channels, const double min[3], const double max[3]);
/* Channel c's voxel_count floats, x fastest, then y, then z. */
ATLAS_API float* atlas_field_builder_channel(AtlasFieldBuilder* builder, int channel);
/* Makes the builder's field the output (the builder is consumed). */
ATLAS_API AtlasStatus atlas_cook_set_output(AtlasCookContext* context, const char* port, AtlasFieldBuilder* builder);
/* Passes an input's field through unchanged (no copy). */
ATLAS_API AtlasStatus atlas_cook_set_output_input(AtlasCookContext* context, const char* port, const char* input_port);
/* Progress 0..1 within the node; returns nonzero when the host cancelled (return soon). */
ATLAS_API int atlas_cook_progress(AtlasCookContext* context, double fraction);
/* The node's error message (the cook fails with it, prefixed with the node). */
ATLAS_API void atlas_cook_fail(AtlasCookContext* context, const char* message);

#ifdef __cplusplus
}
#endif

#endif /* ATLAS_ATLAS_H */
