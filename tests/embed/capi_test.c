/* The C API from C: cook a small graph, read fields, and see errors, progress
 * and cancellation arrive as status codes, messages and callbacks.
 * Usage: capi_test QUICKSTART.yaml [ATLAS_CLI SCRATCH_DIR]
 * With the CLI, a broken graph and an out-of-range --set must give the CLI's messages. */
#ifdef __cplusplus
#error "this test must be compiled as C"
#endif
#define _POSIX_C_SOURCE 200809L /* popen, nanosleep */
#include "atlas/atlas.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static int failures = 0;
static int checks = 0;
#define CHECK(cond)                                                                   \
    do {                                                                              \
        ++checks;                                                                     \
        if (!(cond)) {                                                                \
            ++failures;                                                               \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                             \
    } while (0)
#define CHECK_OK(session, call)                                                                          \
    do {                                                                                                 \
        AtlasStatus st_ = (call);                                                                        \
        ++checks;                                                                                        \
        if (st_ != ATLAS_OK) {                                                                           \
            ++failures;                                                                                  \
            fprintf(stderr, "%s:%d: %s: %s: %s\n", __FILE__, __LINE__, #call, atlas_status_name(st_), \
                    atlas_session_error(session));                                                       \
        }                                                                                                \
    } while (0)

static const char* kGraph =
    "atlas: 1\n"
    "nodes:\n"
    "  base:\n"
    "    type: noise/value\n"
    "    params: {resolution: [16, 8, 4], bounds_min: [0, 0, 0], bounds_max: [160, 80, 40], octaves: 2, seed: 3}\n"
    "  coverage:\n"
    "    type: math/remap\n"
    "    inputs: {in: base}\n"
    "    params: {in_min: 0.25, in_max: 0.75, out_min: 0, out_max: 1, clamp: true}\n"
    "outputs:\n"
    "  - {node: coverage, file: density.exr}\n";

struct Progress {
    int calls;
    int bad_fraction;
};

static void on_progress(void* user, const char* task, double fraction, int done, int total) {
    struct Progress* p = (struct Progress*)user;
    /* Called from worker threads; this test cooks with one job. */
    ++p->calls;
    if (!(fraction >= 0.0 && fraction <= 1.0) || !task || done < 0 || total < done) ++p->bad_fraction;
}

static int cancel_always(void* user) {
    ++*(int*)user;
    return 1;
}

static double remap(double v, double in_min, double in_max) {
    double t = (v - in_min) / (in_max - in_min);
    return t < 0 ? 0 : t > 1 ? 1 : t;
}

static void test_inline_graph(void) {
    AtlasSession* s = NULL;
    CHECK(atlas_session_create(&s) == ATLAS_OK && s);
    CHECK_OK(s, atlas_session_load_text(s, kGraph, "inline.yaml", NULL));
    CHECK(strcmp(atlas_session_error(s), "") == 0);

    AtlasCookOptions o;
    atlas_cook_options_init(&o);
    CHECK(o.struct_size == sizeof o && o.write_outputs == 0 && o.jobs == 0);
    struct Progress progress = {0, 0};
    o.jobs = 1;
    o.progress = on_progress;
    o.user = &progress;
    CHECK_OK(s, atlas_session_cook(s, &o));
    CHECK(progress.calls > 0);
    CHECK(progress.bad_fraction == 0);
    CHECK(atlas_session_node_status(s, "base") && strcmp(atlas_session_node_status(s, "base"), "cooked") == 0);
    CHECK(atlas_session_node_status(s, "nothing") == NULL);
    CHECK(strstr(atlas_session_report_json(s), "\"coverage\"") != NULL);

    AtlasField* base = NULL;
    AtlasField* cov = NULL;
    CHECK_OK(s, atlas_session_get(s, "base", NULL, &o, &base));
    CHECK_OK(s, atlas_session_get(s, "coverage", "out", &o, &cov));
    if (!base || !cov) {
        atlas_session_destroy(s);
        return;
    }
    int res[3];
    double lo[3], hi[3];
    atlas_field_resolution(cov, res);
    atlas_field_bounds(cov, lo, hi);
    CHECK(atlas_field_dimensions(cov) == 3);
    CHECK(res[0] == 16 && res[1] == 8 && res[2] == 4);
    CHECK(lo[0] == 0 && lo[1] == 0 && lo[2] == 0 && hi[0] == 160 && hi[1] == 80 && hi[2] == 40);
    CHECK(atlas_field_channels(cov) == 1);
    CHECK(atlas_field_voxel_count(cov) == 16 * 8 * 4);
    CHECK(strcmp(atlas_field_channel_name(base, 0), "density") == 0);
    CHECK(atlas_field_channel_name(cov, 1) == NULL);
    CHECK(atlas_field_channel_data(cov, -1) == NULL);

    /* coverage is remap(base): check every voxel against the formula. */
    const float* b = atlas_field_channel_data(base, 0);
    const float* c = atlas_field_channel_data(cov, 0);
    size_t n = atlas_field_voxel_count(cov), mismatched = 0, spread = 0;
    for (size_t i = 0; i < n; ++i) {
        if (fabs(c[i] - remap(b[i], 0.25, 0.75)) > 1e-6) ++mismatched;
        if (b[i] != b[0]) ++spread;
    }
    CHECK(mismatched == 0);
    CHECK(spread > 0); /* the noise is not constant */

    /* An edit re-cooks only what depends on it; fields got before stay valid. */
    CHECK_OK(s, atlas_session_set_float(s, "coverage", "in_min", 0.5));
    CHECK_OK(s, atlas_session_cook(s, &o));
    CHECK(strcmp(atlas_session_node_status(s, "coverage"), "cooked") == 0);
    CHECK(strcmp(atlas_session_node_status(s, "base"), "cached") == 0);
    AtlasField* cov2 = NULL;
    CHECK_OK(s, atlas_session_get(s, "coverage", "out", &o, &cov2));
    if (cov2) {
        const float* c2 = atlas_field_channel_data(cov2, 0);
        mismatched = 0;
        for (size_t i = 0; i < n; ++i)
            if (fabs(c2[i] - remap(b[i], 0.5, 0.75)) > 1e-6) ++mismatched;
        CHECK(mismatched == 0);
    }
    /* An int parameter takes an integral float; the text form works as --set. */
    CHECK_OK(s, atlas_session_set_float(s, "base", "octaves", 3.0));
    CHECK_OK(s, atlas_session_set(s, "base", "seed", "11"));

    /* Out of range: the message names the node, the parameter and the range. */
    CHECK(atlas_session_set_int(s, "base", "octaves", 99) == ATLAS_ERROR);
    CHECK(strstr(atlas_session_error(s), "octaves") != NULL);
    CHECK(strstr(atlas_session_error(s), "base") != NULL);
    CHECK(strstr(atlas_session_error(s), "16") != NULL);
    CHECK(atlas_session_set(s, "base", "octavs", "2") == ATLAS_ERROR);
    CHECK(strstr(atlas_session_error(s), "did you mean 'octaves'") != NULL);
    CHECK(atlas_session_set_bool(s, "nobody", "clamp", 1) == ATLAS_ERROR);

    /* Cancellation: a status, no exception; the session still works afterwards. */
    int polls = 0;
    AtlasCookOptions oc;
    atlas_cook_options_init(&oc);
    oc.jobs = 1;
    oc.cancel = cancel_always;
    oc.user = &polls;
    CHECK(atlas_session_cook(s, &oc) == ATLAS_CANCELLED);
    CHECK(polls > 0);
    CHECK(strcmp(atlas_session_error(s), "cancelled") == 0);
    CHECK_OK(s, atlas_session_cook(s, &o));

    /* A field outlives its session. */
    atlas_session_destroy(s);
    CHECK(c[0] == atlas_field_channel_data(cov, 0)[0]);
    atlas_field_release(base);
    atlas_field_release(cov);
    atlas_field_release(cov2);
}

static void test_errors(void) {
    AtlasSession* s = NULL;
    CHECK(atlas_session_create(&s) == ATLAS_OK);
    CHECK(atlas_session_cook(s, NULL) == ATLAS_ERROR); /* no graph loaded */
    CHECK(strstr(atlas_session_error(s), "no graph") != NULL);

    /* A broken graph: an unknown parameter, at its line and column. */
    const char* broken =
        "atlas: 1\n"
        "nodes:\n"
        "  base:\n"
        "    type: noise/value\n"
        "    params: {octavs: 2}\n";
    CHECK(atlas_session_load_text(s, broken, "broken.yaml", NULL) == ATLAS_PARSE_ERROR);
    const char* file = NULL;
    int line = 0, col = 0;
    atlas_session_error_location(s, &file, &line, &col);
    CHECK(file && strcmp(file, "broken.yaml") == 0);
    CHECK(line == 5 && col > 0);
    char prefix[64];
    snprintf(prefix, sizeof prefix, "broken.yaml:5:%d: error:", col);
    CHECK(strncmp(atlas_session_error(s), prefix, strlen(prefix)) == 0);
    CHECK(strstr(atlas_session_error(s), "did you mean 'octaves'") != NULL);

    /* YAML that is not YAML. */
    CHECK(atlas_session_load_text(s, "atlas: 1\nnodes: [\n", "bad.yaml", NULL) == ATLAS_PARSE_ERROR);
    CHECK(strncmp(atlas_session_error(s), "bad.yaml:", 9) == 0);

    CHECK(atlas_session_load(s, "/nonexistent/graph.yaml") != ATLAS_OK);
    CHECK(strstr(atlas_session_error(s), "/nonexistent/graph.yaml") != NULL);

    /* NULL arguments are a status, not a crash. */
    CHECK(atlas_session_get(s, NULL, NULL, NULL, NULL) == ATLAS_INVALID_ARGUMENT);
    CHECK(atlas_session_load(NULL, "x") == ATLAS_INVALID_ARGUMENT);
    atlas_session_destroy(s);
    atlas_session_destroy(NULL);
    atlas_field_release(NULL);
    CHECK(atlas_field_channels(NULL) == 0);
}

static void test_quickstart(const char* path) {
    AtlasSession* s = NULL;
    CHECK(atlas_session_create(&s) == ATLAS_OK);
    CHECK_OK(s, atlas_session_load(s, path));
    AtlasCookOptions o;
    atlas_cook_options_init(&o);
    o.jobs = 2;
    AtlasField* f = NULL;
    CHECK_OK(s, atlas_session_get(s, "coverage", "out", &o, &f));
    if (f) {
        int res[3];
        atlas_field_resolution(f, res);
        CHECK(res[0] == 128 && res[1] == 128 && res[2] == 32);
        const float* d = atlas_field_channel_data(f, 0);
        size_t n = atlas_field_voxel_count(f), outside = 0, ones = 0, zeros = 0;
        for (size_t i = 0; i < n; ++i) {
            if (!(d[i] >= 0.0f && d[i] <= 1.0f)) ++outside;
            ones += d[i] == 1.0f;
            zeros += d[i] == 0.0f;
        }
        CHECK(outside == 0);
        CHECK(zeros > 0 && zeros < n && ones < n); /* clouds and sky both present */
        atlas_field_release(f);
    }
    const char* types = atlas_session_node_types_json(s);
    CHECK(types && strstr(types, "\"noise/value\"") && strstr(types, "\"octaves\""));
    atlas_session_destroy(s);
}

/* Time: a parameter keyed over the graph's time follows atlas_session_set_time. */
static void test_time(void) {
    static const char* graph =
        "atlas: 1\n"
        "time: {start: 0, end: 10, fps: 1}\n"
        "nodes:\n"
        "  c:\n"
        "    type: field/constant\n"
        "    params: {resolution: [2, 2, 1], value: {keys: [[0, 1], [10, 3]], interp: linear}}\n"
        "outputs: []\n";
    AtlasSession* s = NULL;
    CHECK(atlas_session_create(&s) == ATLAS_OK);
    CHECK_OK(s, atlas_session_load_text(s, graph, "time.yaml", NULL));
    const double times[3] = {0, 5, 20};
    const float expected[3] = {1.0f, 2.0f, 3.0f}; /* after the last key: the last value */
    for (int i = 0; i < 3; ++i) {
        CHECK_OK(s, atlas_session_set_time(s, times[i]));
        AtlasField* f = NULL;
        CHECK_OK(s, atlas_session_get(s, "c", "out", NULL, &f));
        if (f) {
            CHECK(atlas_field_channel_data(f, 0)[0] == expected[i]);
            atlas_field_release(f);
        }
    }
    CHECK(atlas_session_set_time(s, 1.0 / 0.0) == ATLAS_INVALID_ARGUMENT);
    atlas_session_destroy(s);
}

/* Meshes and points: a box mesh and samples filling it. */
static void test_mesh_and_points(void) {
    static const char* graph =
        "atlas: 1\n"
        "nodes:\n"
        "  box:\n"
        "    type: volume/mesh_primitive\n"
        "    params: {shape: box, center: [100, 200, 50], half_size: [10, 20, 5]}\n"
        "  fill:\n"
        "    type: volume/interior_fill\n"
        "    inputs: {mesh: box}\n"
        "    params: {target_samples: 200}\n"
        "outputs: []\n";
    AtlasSession* s = NULL;
    CHECK(atlas_session_create(&s) == ATLAS_OK);
    CHECK_OK(s, atlas_session_load_text(s, graph, "mesh.yaml", NULL));
    AtlasMesh* m = NULL;
    CHECK_OK(s, atlas_session_get_mesh(s, "box", NULL, NULL, &m));
    if (m) {
        size_t nv = atlas_mesh_vertex_count(m), nt = atlas_mesh_triangle_count(m), bad = 0;
        const float* v = atlas_mesh_vertices(m);
        const uint32_t* t = atlas_mesh_triangles(m);
        CHECK(nv >= 8 && nt >= 12 && v && t);
        for (size_t i = 0; i < nv; ++i) /* every vertex on the box's surface */
            if (fabs(fabs(v[3 * i] - 100) - 10) > 1e-3 && fabs(fabs(v[3 * i + 1] - 200) - 20) > 1e-3 &&
                fabs(fabs(v[3 * i + 2] - 50) - 5) > 1e-3)
                ++bad;
        for (size_t i = 0; i < 3 * nt; ++i) bad += t[i] >= nv;
        CHECK(bad == 0);
        atlas_mesh_release(m);
    }
    AtlasField* not_a_field = NULL;
    CHECK(atlas_session_get(s, "box", NULL, NULL, &not_a_field) == ATLAS_INVALID_ARGUMENT && !not_a_field);
    CHECK(strstr(atlas_session_error(s), "is a mesh, not a field") != NULL);

    AtlasPoints* p = NULL;
    CHECK_OK(s, atlas_session_get_points(s, "fill", NULL, NULL, &p));
    if (p) {
        size_t n = atlas_points_count(p), outside = 0;
        const float* x = atlas_points_positions(p);
        CHECK(n > 10 && x);
        for (size_t i = 0; i < n; ++i)
            outside += fabs(x[3 * i] - 100) > 10.001 || fabs(x[3 * i + 1] - 200) > 20.001 || fabs(x[3 * i + 2] - 50) > 5.001;
        CHECK(outside == 0);
        CHECK(atlas_points_attribute_count(p) >= 2);
        const float* r = atlas_points_attribute(p, "radius");
        CHECK(r && r[0] > 0);
        CHECK(atlas_points_attribute(p, "nothing") == NULL && atlas_points_attribute_name(p, 99) == NULL);
        CHECK(strcmp(atlas_points_attribute_name(p, 0), "radius") == 0); /* name order */
        atlas_points_release(p);
    }
    CHECK(atlas_session_get_points(s, "box", NULL, NULL, &p) == ATLAS_INVALID_ARGUMENT && !p);
    atlas_session_destroy(s);
}

/* A node type written in C: out = in * gain (+ offset per channel), hashed and cached. */
static atomic_int scale_calls;

static int cook_scale(void* user, AtlasCookContext* c) {
    atomic_fetch_add(&scale_calls, 1);
    CHECK(user == (void*)&scale_calls);
    double gain = 0;
    int64_t unused = 0;
    CHECK(atlas_cook_param_float(c, "gain", &gain) == ATLAS_OK);
    CHECK(atlas_cook_param_int(c, "gain", &unused) == ATLAS_INVALID_ARGUMENT); /* a float, not an int */
    CHECK(atlas_cook_param_float(c, "nothing", &gain) == ATLAS_INVALID_ARGUMENT);
    const char* mode = NULL;
    CHECK(atlas_cook_param_string(c, "mode", &mode) == ATLAS_OK && mode);
    const AtlasField* in = atlas_cook_input(c, "in");
    if (!in) {
        atlas_cook_fail(c, "no input");
        return 1;
    }
    if (strcmp(mode, "pass") == 0) return atlas_cook_set_output_input(c, "out", "in") == ATLAS_OK ? 0 : 1;
    int res[3];
    double lo[3], hi[3];
    atlas_field_resolution(in, res);
    atlas_field_bounds(in, lo, hi);
    AtlasFieldBuilder* b = atlas_cook_new_field(c, 3, res, 1, lo, hi);
    if (!b) return 1;
    const float* src = atlas_field_channel_data(in, 0);
    float* dst = atlas_field_builder_channel(b, 0);
    for (size_t i = 0; i < atlas_field_voxel_count(in); ++i) dst[i] = (float)(src[i] * gain);
    if (atlas_cook_progress(c, 1.0)) return 1;
    return atlas_cook_set_output(c, "out", b) == ATLAS_OK ? 0 : 1;
}

static int cook_broken(void* user, AtlasCookContext* c) {
    (void)user;
    atlas_cook_fail(c, "no clouds today");
    return 1;
}

static const char* kScaleDecl =
    "{\"name\": \"host/scale\", \"version\": 1, \"doc\": \"Multiplies a field by a gain.\","
    " \"inputs\": [{\"name\": \"in\", \"type\": \"field3d\", \"doc\": \"field\"}],"
    " \"outputs\": [{\"name\": \"out\", \"type\": \"field3d\"}],"
    " \"params\": [{\"name\": \"gain\", \"type\": \"float\", \"default\": 2, \"min\": 0, \"max\": 10, \"doc\": \"factor\"},"
    "              {\"name\": \"mode\", \"type\": \"enum\", \"default\": \"scale\", \"choices\": [\"scale\", \"pass\"]}]}";

static void test_c_node_types(void) {
    AtlasRegistry* reg = NULL;
    CHECK(atlas_registry_create(&reg) == ATLAS_OK && reg);
    atomic_init(&scale_calls, 0);
    CHECK(atlas_registry_add_node(reg, kScaleDecl, cook_scale, &scale_calls) == ATLAS_OK);
    CHECK(atlas_registry_add_node(reg, kScaleDecl, cook_scale, NULL) == ATLAS_ERROR); /* a duplicate */
    CHECK(atlas_registry_add_node(reg, "{\"name\": \"host/x\", \"outputs\": [{\"name\": \"out\", \"type\": \"volume\"}]}",
                                  cook_broken, NULL) == ATLAS_INVALID_ARGUMENT);
    CHECK(strstr(atlas_registry_error(reg), "unknown port type 'volume'") != NULL);
    CHECK(atlas_registry_add_node(reg, "{not json", cook_broken, NULL) == ATLAS_INVALID_ARGUMENT);
    /* An int3 default past int's range was a float-to-int overflow (UBSan): refused by name. */
    CHECK(atlas_registry_add_node(reg,
                                  "{\"name\": \"host/big\", \"outputs\": [{\"name\": \"out\", \"type\": \"field3d\"}], "
                                  "\"params\": [{\"name\": \"res\", \"type\": \"int3\", \"default\": [1e20, 1, 1]}]}",
                                  cook_broken, NULL) == ATLAS_INVALID_ARGUMENT);
    CHECK(strstr(atlas_registry_error(reg), "within +-2^31") != NULL);
    CHECK(atlas_registry_add_node(reg, "{\"name\": \"host/broken\", \"outputs\": [{\"name\": \"out\", \"type\": \"field3d\"}]}",
                                  cook_broken, NULL) == ATLAS_OK);

    AtlasSession* s = NULL;
    CHECK(atlas_session_create_with_registry(reg, &s) == ATLAS_OK);
    atlas_registry_destroy(reg); /* the session has its own copy */
    static const char* graph =
        "atlas: 1\n"
        "nodes:\n"
        "  base:\n"
        "    type: noise/value\n"
        "    params: {resolution: [16, 8, 4], bounds_min: [0, 0, 0], bounds_max: [160, 80, 40], octaves: 2, seed: 3}\n"
        "  scaled: {type: host/scale, inputs: {in: base}, params: {gain: 3}}\n"
        "  shaped: {type: math/remap, inputs: {in: scaled}, params: {in_min: 0, in_max: 3}}\n"
        "  same: {type: host/scale, inputs: {in: base}, params: {mode: pass}}\n"
        "  broken: {type: host/broken}\n"
        "outputs:\n  - {node: shaped, file: shaped.exr}\n";
    CHECK_OK(s, atlas_session_load_text(s, graph, "c_nodes.yaml", NULL));
    AtlasCookOptions o;
    atlas_cook_options_init(&o);
    o.jobs = 2;
    CHECK_OK(s, atlas_session_cook(s, &o));
    CHECK(atomic_load(&scale_calls) == 1);
    AtlasField *base = NULL, *scaled = NULL, *shaped = NULL, *same = NULL;
    CHECK_OK(s, atlas_session_get(s, "base", NULL, &o, &base));
    CHECK_OK(s, atlas_session_get(s, "scaled", NULL, &o, &scaled));
    CHECK_OK(s, atlas_session_get(s, "shaped", NULL, &o, &shaped));
    CHECK_OK(s, atlas_session_get(s, "same", NULL, &o, &same));
    CHECK(atomic_load(&scale_calls) == 2); /* 'same' cooked for the get; the rest came from the cache */
    if (base && scaled && shaped && same) {
        const float *b = atlas_field_channel_data(base, 0), *x = atlas_field_channel_data(scaled, 0);
        const float *y = atlas_field_channel_data(shaped, 0);
        size_t bad = 0;
        for (size_t i = 0; i < atlas_field_voxel_count(base); ++i) {
            bad += fabs(x[i] - b[i] * 3.0) > 1e-5;
            bad += fabs(y[i] - (b[i] < 0 ? 0 : b[i] > 1 ? 1 : b[i])) > 1e-5;
        }
        CHECK(bad == 0);
        CHECK(atlas_field_channel_data(same, 0) == b); /* passed through: the same memory */
        double lo[3], hi[3];
        atlas_field_bounds(scaled, lo, hi);
        CHECK(hi[0] == 160 && hi[1] == 80 && hi[2] == 40);
    }
    /* A parameter edit re-cooks the C node; validation uses its declaration. */
    CHECK(atlas_session_set_float(s, "scaled", "gain", 11) == ATLAS_ERROR && strstr(atlas_session_error(s), "gain"));
    CHECK(atlas_session_set(s, "scaled", "mode", "fast") == ATLAS_ERROR);
    CHECK_OK(s, atlas_session_set_float(s, "scaled", "gain", 0.5));
    CHECK_OK(s, atlas_session_cook(s, &o));
    CHECK(strcmp(atlas_session_node_status(s, "scaled"), "cooked") == 0);
    CHECK(strcmp(atlas_session_node_status(s, "base"), "cached") == 0);
    /* A failing C node names itself. */
    AtlasField* none = NULL;
    CHECK(atlas_session_get(s, "broken", NULL, &o, &none) == ATLAS_ERROR && !none);
    CHECK(strstr(atlas_session_error(s), "node 'broken' (host/broken): no clouds today") != NULL);
    atlas_field_release(base);
    atlas_field_release(scaled);
    atlas_field_release(shaped);
    atlas_field_release(same);
    atlas_session_destroy(s);
}

/* One call at a time per session: a second thread gets ATLAS_BUSY, another session works. */
struct Hold {
    atomic_int started, release;
    AtlasSession* s;
    AtlasStatus status;
};

static int hold_cancel(void* user) {
    struct Hold* h = (struct Hold*)user;
    atomic_store(&h->started, 1);
    while (!atomic_load(&h->release)) {
    }
    return 0;
}

static void* hold_cook(void* user) {
    struct Hold* h = (struct Hold*)user;
    AtlasCookOptions o;
    atlas_cook_options_init(&o);
    o.jobs = 1;
    o.cancel = hold_cancel;
    o.user = h;
    h->status = atlas_session_cook(h->s, &o);
    return NULL;
}

/* A session cooking kGraph on thread *t, held in its cancel callback until h->release. */
static void start_held_cook(struct Hold* h, const char* name, pthread_t* t) {
    atomic_init(&h->started, 0);
    atomic_init(&h->release, 0);
    h->s = NULL;
    h->status = ATLAS_ERROR;
    CHECK(atlas_session_create(&h->s) == ATLAS_OK);
    CHECK_OK(h->s, atlas_session_load_text(h->s, kGraph, name, NULL));
    CHECK(pthread_create(t, NULL, hold_cook, h) == 0);
    while (!atomic_load(&h->started)) {
    }
}

static void test_one_call_at_a_time(void) {
    struct Hold h;
    pthread_t t;
    start_held_cook(&h, "busy.yaml", &t);
    CHECK(atlas_session_set_float(h.s, "coverage", "in_min", 0.5) == ATLAS_BUSY);
    CHECK(strcmp(atlas_status_name(ATLAS_BUSY), "busy") == 0);
    AtlasSession* other = NULL;
    CHECK(atlas_session_create(&other) == ATLAS_OK);
    CHECK_OK(other, atlas_session_load_text(other, kGraph, "other.yaml", NULL));
    CHECK_OK(other, atlas_session_cook(other, NULL));
    atlas_session_destroy(other);
    atomic_store(&h.release, 1);
    pthread_join(t, NULL);
    CHECK(h.status == ATLAS_OK);
    CHECK_OK(h.s, atlas_session_set_float(h.s, "coverage", "in_min", 0.5)); /* free again */
    atlas_session_destroy(h.s);
}

/* Destroying a session while another thread cooks on it waits for the cook
 * (it was a use-after-free that ASan reported). The cook is released only
 * after destroy has begun; destroy must not return before the cook did. */
static void* release_later(void* user) {
    struct Hold* h = (struct Hold*)user;
    struct timespec ts = {0, 50 * 1000 * 1000};
    nanosleep(&ts, NULL);
    atomic_store(&h->release, 1);
    return NULL;
}

static void test_destroy_during_a_cook(void) {
    struct Hold h;
    pthread_t cook, releaser;
    start_held_cook(&h, "destroy.yaml", &cook);
    CHECK(pthread_create(&releaser, NULL, release_later, &h) == 0);
    atlas_session_destroy(h.s); /* waits for the cook */
    CHECK(atomic_load(&h.release) == 1);
    pthread_join(cook, NULL);
    pthread_join(releaser, NULL);
    CHECK(h.status == ATLAS_OK);
}

/* Runs the CLI and returns its combined output (static buffer). */
static const char* run_cli(const char* command) {
    static char out[8192];
    size_t n = 0;
    out[0] = 0;
    FILE* p = popen(command, "r");
    if (!p) return out;
    while (n + 1 < sizeof out && fgets(out + n, (int)(sizeof out - n), p)) n += strlen(out + n);
    pclose(p);
    return out;
}

static void test_same_messages_as_the_cli(const char* cli, const char* dir) {
    char broken[1024], good[1024], cmd[4096];
    snprintf(broken, sizeof broken, "%s/capi_broken.yaml", dir);
    snprintf(good, sizeof good, "%s/capi_good.yaml", dir);
    FILE* f = fopen(broken, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs("atlas: 1\nnodes:\n  base:\n    type: noise/value\n    params: {octavs: 2}\noutputs: []\n", f);
    fclose(f);
    f = fopen(good, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs("atlas: 1\nnodes:\n  base:\n    type: noise/value\n    params: {octaves: 2}\n"
          "outputs:\n  - {node: base, file: base.exr}\n", f);
    fclose(f);

    AtlasSession* s = NULL;
    CHECK(atlas_session_create(&s) == ATLAS_OK);
    CHECK(atlas_session_load(s, broken) == ATLAS_PARSE_ERROR);
    snprintf(cmd, sizeof cmd, "'%s' validate '%s' 2>&1", cli, broken);
    const char* out = run_cli(cmd);
    CHECK(strlen(atlas_session_error(s)) > 20 && strstr(out, atlas_session_error(s)) != NULL);
    if (!strstr(out, atlas_session_error(s))) fprintf(stderr, "C API: %s\nCLI:   %s\n", atlas_session_error(s), out);

    CHECK_OK(s, atlas_session_load(s, good));
    CHECK(atlas_session_set(s, "base", "octaves", "99") == ATLAS_ERROR);
    snprintf(cmd, sizeof cmd, "'%s' cook '%s' --out '%s/capi_out' --set base.octaves=99 2>&1", cli, good, dir);
    out = run_cli(cmd);
    CHECK(strlen(atlas_session_error(s)) > 20 && strstr(out, atlas_session_error(s)) != NULL);
    if (!strstr(out, atlas_session_error(s))) fprintf(stderr, "C API: %s\nCLI:   %s\n", atlas_session_error(s), out);
    atlas_session_destroy(s);
}

/* atlas_session_preview: the picture `atlas preview` draws, through the session, at a
 * proxy; an edit re-renders; bad options are refused with the option's name. */
static const char* kCloud =
    "atlas: 1\n"
    "nodes:\n"
    "  density: {type: volume/metaballs, params: {resolution: [32, 32, 16], bounds_max: [1000, 1000, 500], kernel: sphere, blend: max,\n"
    "            spheres: 500 500 220 160}}\n"
    "  sdf: {type: volume/sdf, inputs: {in: density}, params: {iso: 0.5}}\n"
    "  nvdf: {type: volume/nvdf, inputs: {sdf: sdf}, params: {depth: 30}}\n"
    "outputs:\n"
    "  - {node: nvdf, port: vdb_set, file: cloud.vdb}\n";

static void test_preview(void) {
    AtlasSession* s = NULL;
    CHECK_OK(s, atlas_session_create(&s));
    CHECK_OK(s, atlas_session_load_text(s, kCloud, "cloud.yaml", "."));
    AtlasCookOptions o;
    atlas_cook_options_init(&o);
    o.proxy = 2;
    AtlasField* img = NULL;
    CHECK_OK(s, atlas_session_preview(s, "{\"size\": [40, 24], \"noise\": \"none\", \"view\": \"orbit\"}", &o, &img));
    CHECK(img != NULL);
    if (img) {
        int res[3];
        atlas_field_resolution(img, res);
        CHECK(res[0] == 40 && res[1] == 24 && atlas_field_channels(img) == 4);
        const float* t = atlas_field_channel_data(img, 3);
        float tmin = 1, tmax = 0;
        for (int i = 0; i < 40 * 24; ++i) {
            if (t[i] < tmin) tmin = t[i];
            if (t[i] > tmax) tmax = t[i];
        }
        CHECK(tmin < 0.5f && tmax > 0.99f && tmax <= 1.0f); /* the cloud covers some pixels, sky others */
        atlas_field_release(img);
    }
    img = NULL;
    CHECK(atlas_session_preview(s, "{\"sizes\": 3}", &o, &img) != ATLAS_OK && img == NULL);
    CHECK(strstr(atlas_session_error(s), "preview option 'sizes' does not exist") != NULL);
    CHECK(atlas_session_preview(s, "{not json", &o, &img) == ATLAS_INVALID_ARGUMENT);
    CHECK(img == NULL);
    /* A proxy cook never writes. */
    o.write_outputs = 1;
    CHECK(atlas_session_cook(s, &o) != ATLAS_OK);
    CHECK(strstr(atlas_session_error(s), "never written as final outputs") != NULL);
    atlas_session_destroy(s);
}

int main(int argc, char** argv) {
    if (argc != 2 && argc != 4) {
        fprintf(stderr, "usage: capi_test QUICKSTART.yaml [ATLAS_CLI SCRATCH_DIR]\n");
        return 2;
    }
    CHECK(strlen(atlas_version()) >= 5);
    test_inline_graph();
    test_errors();
    test_quickstart(argv[1]);
    test_time();
    test_one_call_at_a_time();
    test_destroy_during_a_cook();
    test_mesh_and_points();
    test_c_node_types();
    test_preview();
    if (argc == 4) test_same_messages_as_the_cli(argv[2], argv[3]);
    printf("%d passed, %d failed\n", checks - failures, failures);
    return failures ? 1 : 0;
}
