// The atlas Python module (_atlas, wrapped by python/atlas/__init__.py):
// Session, errors as exceptions, declarations as plain data.
#include "bindings.h"
#include "errors.h"
#include "params.h"

#include "atlas/graph/node_docs.h"
#include "atlas/preview/graph_preview.h"
#include "atlas/render/image_out.h"

#include <pybind11/numpy.h>

#include <atomic>

namespace atlas::python {

namespace {

const ParamDecl* find_decl(const Session& s, const std::string& node, const std::string& param) {
    const GraphNode* n = s.graph().find(node);
    const NodeType* t = n ? s.registry().find(n->type) : nullptr;
    return t ? t->decl.find_param(param) : nullptr;
}

// Callbacks: Python callables run with the GIL taken; a Python exception in
// one becomes an atlas::Error (the cook fails with its message).
ProgressSink make_sink(const py::object& progress, const py::object& cancel) {
    ProgressSink sink;
    if (!progress.is_none()) {
        SharedPyObject fn(progress);
        sink.on_progress = [fn](const ProgressEvent& e) {
            py::gil_scoped_acquire gil;
            try {
                fn.get()(e.fraction, e.task, e.done, e.total);
            } catch (py::error_already_set& err) {
                throw Error("progress callback raised " + python_error_message(err));
            }
        };
    }
    if (!cancel.is_none()) {
        SharedPyObject fn(cancel);
        sink.is_cancelled = [fn]() {
            py::gil_scoped_acquire gil;
            try {
                return bool(py::bool_(fn.get()()));
            } catch (py::error_already_set& err) {
                throw Error("cancel callback raised " + python_error_message(err));
            }
        };
    }
    return sink;
}

CookOptions make_options(const py::object& outputs, int jobs, bool write_outputs, const py::object& out_dir,
                         const py::object& cache_dir, bool checked, const py::object& memory_budget,
                         const py::object& progress, const py::object& cancel) {
    CookOptions o;
    if (!outputs.is_none()) o.outputs = outputs.cast<std::vector<std::string>>();
    o.jobs = jobs;
    o.write_outputs = write_outputs;
    if (!out_dir.is_none()) o.out_dir = py::str(out_dir).cast<std::string>();
    if (!cache_dir.is_none()) o.cache_dir = std::filesystem::path(py::str(cache_dir).cast<std::string>());
    o.checked = checked;
    if (!memory_budget.is_none()) o.memory_budget = memory_budget.cast<uint64_t>();
    o.progress = make_sink(progress, cancel);
    return o;
}

py::dict result_to_python(const CookResult& r) {
    py::dict nodes;
    for (const auto& [name, n] : r.nodes) {
        py::dict d;
        d["type"] = n.type;
        d["status"] = n.status;
        d["reason"] = n.reason;
        d["hash"] = n.hash;
        d["seconds"] = n.seconds;
        d["bytes"] = n.bytes;
        d["metrics"] = n.metrics;
        d["warnings"] = n.warnings;
        nodes[py::str(name)] = d;
    }
    py::list outputs;
    for (const auto& o : r.outputs) {
        py::dict d;
        d["node"] = o.node;
        d["port"] = o.port;
        d["file"] = o.file;
        d["format"] = o.format;
        py::list written;
        for (const auto& p : o.written) written.append(p.string());
        d["written"] = written;
        d["metrics"] = o.metrics;
        d["status"] = o.status;
        d["seconds"] = o.seconds;
        if (!o.error.empty()) d["error"] = o.error;
        outputs.append(d);
    }
    py::dict d;
    d["nodes"] = nodes;
    d["outputs"] = outputs;
    d["seconds"] = r.seconds;
    d["jobs"] = r.jobs;
    d["checked"] = r.checked;
    return d;
}

py::list graph_nodes(const Session& s) {
    py::list out;
    const Graph& g = s.graph();
    for (const GraphNode& n : g.nodes) {
        const NodeType* t = s.registry().find(n.type);
        py::dict d;
        d["name"] = n.name;
        d["type"] = n.type;
        d["where"] = n.where.str();
        py::dict params, explicit_params;
        if (t) {
            auto resolved = resolved_params(n, *t);
            for (const ParamDecl& p : t->decl.params()) params[py::str(p.name)] = param_to_python(resolved.at(p.name), p.type);
            for (const auto& [name, setting] : n.params) {
                const ParamDecl* p = t->decl.find_param(name);
                explicit_params[py::str(name)] = param_to_python(setting.value, p ? p->type : ParamType::String);
            }
        }
        d["params"] = params;
        d["explicit"] = explicit_params;
        py::dict inputs;
        for (const auto& [port, b] : n.inputs) inputs[py::str(port)] = py::make_tuple(b.node, b.port);
        d["inputs"] = inputs;
        out.append(d);
    }
    return out;
}

py::list graph_outputs(const Session& s) {
    py::list out;
    for (const GraphOutput& o : s.graph().outputs) {
        py::dict d;
        d["node"] = o.node;
        d["port"] = o.port;
        d["file"] = o.file;
        d["format"] = o.format;
        d["options"] = o.options;
        d["where"] = o.where.str();
        out.append(d);
    }
    return out;
}

// A Session as Python holds it: calls on one Session from two Python threads
// at once (possible, since cook releases the GIL) are refused, not a data race.
struct PySession {
    explicit PySession(NodeRegistry registry) : session(std::move(registry)) {}
    Session session;
    std::atomic<bool> busy{false};
};

class BusyGuard {
public:
    explicit BusyGuard(PySession& p) : p_(p) {
        if (p_.busy.exchange(true))
            throw Error("this atlas.Session is in use by another thread (one call at a time per Session; "
                        "use one Session per thread)");
    }
    ~BusyGuard() { p_.busy = false; }
    BusyGuard(const BusyGuard&) = delete;
    BusyGuard& operator=(const BusyGuard&) = delete;

private:
    PySession& p_;
};

} // namespace

// A Python value as the text of a preview option ("640,360" for (640, 360)).
std::string option_text(const py::handle& v) {
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
        std::string out;
        for (const py::handle& x : v) out += (out.empty() ? "" : ",") + option_text(x);
        return out;
    }
    return py::str(v).cast<std::string>();
}

// A host's dict of preview options ({"size": (640, 360), ...}) as PreviewOptions.
render::PreviewOptions preview_options_from(const py::object& options) {
    render::PreviewOptions po;
    std::vector<std::pair<std::string, std::string>> settings;
    if (!options.is_none())
        for (const auto& item : options.cast<py::dict>()) settings.emplace_back(py::str(item.first).cast<std::string>(), option_text(item.second));
    preview::set_preview_options(po, settings);
    return po;
}

preview::GraphPreviewOptions preview_how(int proxy, const std::string& mode, const std::string& noise) {
    preview::GraphPreviewOptions how;
    how.proxy = proxy;
    how.mode = mode;
    how.noise = noise;
    return how;
}

// A picture as a NumPy array, rows from the top: float32 (h, w, channels).
py::array_t<float> image_to_numpy(const Field2D& img) {
    const int w = img.width(), h = img.height(), nc = img.channels();
    py::array_t<float> a({py::ssize_t(h), py::ssize_t(w), py::ssize_t(nc)});
    auto m = a.mutable_unchecked<3>();
    for (int row = 0; row < h; ++row)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < nc; ++c) m(row, x, c) = img.at(c, x, h - 1 - row);
    return a;
}

} // namespace atlas::python

using namespace atlas;
using namespace atlas::python;

PYBIND11_MODULE(_atlas, m) {
    m.doc() = "Atlas: node graphs cooked into volumetric cloud data (bindings over libatlas).";
    m.attr("__version__") = ATLAS_VERSION_STRING;
    // pybind11 looks numpy's C API up in a function-local static on first use;
    // two threads reaching it at once (each with its own Session) deadlocked:
    // one inside the static's guard imports numpy and yields the GIL, the
    // other holds the GIL and waits on the guard. Done here, once, under the
    // import lock.
    py::module_::import("numpy");
    (void)py::dtype::of<float>();
    (void)py::array_t<float>(std::vector<py::ssize_t>{0});

    bind_errors(m);
    bind_fields(m);
    bind_python_nodes(m);

    py::class_<PySession>(m, "Session", R"doc(
A loaded graph and its in-memory cache (atlas::Session). Edit parameters and
re-cook: only what changed cooks again. Not thread-safe: one call at a time
per Session (cook releases the GIL, so other Python threads run meanwhile).)doc")
        .def(py::init([](const py::object& registry) {
                 if (registry.is_none()) return std::make_unique<PySession>(builtin_nodes());
                 return std::make_unique<PySession>(registry.cast<const NodeRegistry&>());
             }),
             py::arg("registry") = py::none(), "A session over `registry` (an atlas.NodeRegistry; default: the built-in node types).")
        .def("load", [](PySession& ps, const py::object& path) {
                 BusyGuard guard(ps);
                 Session& s = ps.session; s.load(py::str(path).cast<std::string>()); }, py::arg("path"),
             "Loads (parses and validates) a graph file; raises atlas.ParseError with file:line:col.")
        .def("load_text", [](PySession& ps, const std::string& text, const std::string& name, const py::object& base_dir) {
                 BusyGuard guard(ps);
                 Session& s = ps.session;
                 s.load_text(text, name, base_dir.is_none() ? std::filesystem::current_path() : std::filesystem::path(py::str(base_dir).cast<std::string>()));
             }, py::arg("text"), py::arg("name") = "<text>", py::arg("base_dir") = py::none(),
             "Loads a graph from YAML text; `name` is used in messages, relative paths resolve against base_dir (default: the current directory).")
        .def("set", [](PySession& ps, const std::string& node, const std::string& param, const py::object& value) {
                 BusyGuard guard(ps);
                 Session& s = ps.session;
                 const ParamDecl* d = find_decl(s, node, param);
                 if (!d) {
                     // Let the library name what is wrong (unknown node or parameter, with a hint).
                     s.set_text(node, param, py::str(value).cast<std::string>());
                     return;
                 }
                 s.set(node, param, param_from_python(value, d->type, node + "." + param));
             }, py::arg("node"), py::arg("param"), py::arg("value"),
             "Overrides NODE.PARAM with a Python value, validated against the declaration (type, range, choices).")
        .def("set_time", [](PySession& ps, double t) {
                 BusyGuard guard(ps);
                 ps.session.set_time(t);
             }, py::arg("t"),
             "Sets the graph's time in seconds (docs/graph-format.md, \"Time\"): keyed parameters take their values at t; "
             "the next cook re-cooks only the nodes that read them.")
        .def("time_range", [](PySession& ps) -> py::object {
                 const auto& t = ps.session.graph().time;
                 if (!t) return py::none();
                 return py::make_tuple(t->start, t->end, t->fps);
             },
             "The graph's time block as (start, end, fps) in seconds and frames per second, or None.")
        .def("set_text", [](PySession& ps, const std::string& node, const std::string& param, const std::string& text) {
                 BusyGuard guard(ps);
                 ps.session.set_text(node, param, text);
             }, py::arg("node"), py::arg("param"), py::arg("text"),
             "Overrides NODE.PARAM from text as the CLI's --set spells it ('0.5', '[1, 2, 3]', 'name').")
        .def("cook", [](PySession& ps, const py::object& outputs, int jobs, bool write_outputs, const py::object& out_dir,
                        const py::object& cache_dir, bool checked, const py::object& memory_budget, const py::object& progress,
                        const py::object& cancel, bool keep_going, int proxy, bool keep_values) {
                 BusyGuard guard(ps);
                 Session& s = ps.session;
                 CookOptions o = make_options(outputs, jobs, write_outputs, out_dir, cache_dir, checked, memory_budget, progress, cancel);
                 o.keep_going = keep_going;
                 o.proxy = proxy;
                 o.keep_values = keep_values;
                 CookResult r;
                 {
                     py::gil_scoped_release nogil;
                     r = s.cook(o);
                 }
                 return result_to_python(r);
             },
             py::arg("outputs") = py::none(), py::arg("jobs") = 0, py::arg("write_outputs") = false, py::arg("out_dir") = py::none(),
             py::arg("cache_dir") = py::none(), py::arg("checked") = false, py::arg("memory_budget") = py::none(),
             py::arg("progress") = py::none(), py::arg("cancel") = py::none(), py::arg("keep_going") = false, py::arg("proxy") = 1,
             py::arg("keep_values") = true,
             R"doc(Cooks the graph's outputs (or those named) and returns the report as a dict:
{"nodes": {name: {"status": "cooked"|"cached"|"skipped", "type", "reason", "hash", "seconds", "bytes", "metrics", "warnings"}}, "outputs": [...], ...}.
write_outputs=True also writes the output files into out_dir (atomically). The GIL is released while
cooking; progress(fraction, task, done, total) and cancel() -> bool are called from worker threads
with the GIL taken. Raises atlas.CancelledError when cancel() returns true. keep_going=True: an output
whose writer fails is reported with "status": "failed" and its "error" (and a warning), and the other
outputs are written (an editor's edit); otherwise the cook raises and writes nothing. proxy=P: every world
grid at 1/P of its cells per axis (values only: a proxy cook never writes outputs). keep_values=False: a
one-shot cook (a build step, as `atlas cook`): each value is freed once the nodes reading it are done and
the outputs it feeds are written, and the session keeps none for the next cook.)doc")
        .def("preview", [](PySession& ps, const py::object& options, int proxy, int jobs, const py::object& cache_dir, const std::string& mode,
                           const std::string& noise, bool tone_mapped, const py::object& progress, const py::object& cancel) {
                 BusyGuard guard(ps);
                 const render::PreviewOptions po = preview_options_from(options);
                 preview::GraphPreviewOptions how = preview_how(proxy, mode, noise);
                 how.jobs = jobs;
                 if (!cache_dir.is_none()) how.cache_dir = std::filesystem::path(py::str(cache_dir).cast<std::string>());
                 how.progress = make_sink(progress, cancel);
                 std::optional<render::PreviewFrame> f;
                 {
                     py::gil_scoped_release nogil;
                     f.emplace(preview::preview_session(ps.session, po, how));
                 }
                 if (!tone_mapped) return image_to_numpy(f->image);
                 return image_to_numpy(render::tone_map(f->image, po.exposure));
             },
             py::arg("options") = py::none(), py::arg("proxy") = 1, py::arg("jobs") = 0, py::arg("cache_dir") = py::none(),
             py::arg("mode") = "auto", py::arg("noise") = "auto", py::arg("tone_mapped") = false, py::arg("progress") = py::none(),
             py::arg("cancel") = py::none(),
             R"doc(Renders what the graph writes, as `atlas preview GRAPH` does, through this session: values stay
in memory, so after an edit only the changed nodes cook. Nothing is written. `options` is a dict of
preview options by their docs/options.md names, as values or text: {"size": (640, 360), "view": "orbit",
"sun_azimuth": 200}. proxy=4 cooks every world grid at a quarter of its cells per axis (for
interaction). Returns a float32 NumPy array (height, width, 4) of linear radiance r, g, b and view
transmittance, rows from the top; tone_mapped=True: the PNG's sRGB values in 0..1 (height, width, 3).)doc")
        .def("preview_settings", [](PySession& ps, const py::object& options, int proxy, const std::string& mode, const std::string& noise) {
                 BusyGuard guard(ps);
                 const render::PreviewOptions po = preview_options_from(options);
                 const preview::GraphPreviewOptions how = preview_how(proxy, mode, noise);
                 std::optional<preview::GraphPreview> p;
                 {
                     py::gil_scoped_release nogil;
                     p.emplace(preview::prepare_graph_preview(ps.session, po, how));
                 }
                 const render::RenderSettings& rs = p->job.settings;
                 auto v3 = [](const auto& v) { return py::make_tuple(double(v[0]), double(v[1]), double(v[2])); };
                 const double four_pi = 4 * 3.14159265358979323846;
                 const Vec3d sun = rs.sun_direction / length(rs.sun_direction);
                 py::dict d, cam, sund, sky, phase;
                 cam["position"] = v3(rs.camera.position);
                 cam["look_at"] = v3(rs.camera.look_at);
                 cam["up"] = v3(rs.camera.up);
                 cam["fov_y_deg"] = rs.camera.fov_deg;
                 sund["direction_to_sun"] = v3(sun);
                 sund["irradiance_rgb"] = py::make_tuple(four_pi * rs.sun_colour[0], four_pi * rs.sun_colour[1], four_pi * rs.sun_colour[2]);
                 sky["zenith_rgb"] = v3(rs.sky_colour);
                 sky["horizon_rgb"] = v3(rs.sky_horizon.value_or(rs.sky_colour));
                 phase["g_forward"] = rs.hg_forward;
                 phase["g_back"] = rs.hg_back;
                 phase["forward_weight"] = rs.hg_forward_weight;
                 d["camera"] = cam;
                 d["sun"] = sund;
                 d["sky"] = sky;
                 d["phase"] = phase;
                 d["width"] = rs.width;
                 d["height"] = rs.height;
                 d["extinction_per_metre"] = rs.extinction;
                 d["artistic"] = rs.artistic;
                 return d;
             },
             py::arg("options") = py::none(), py::arg("proxy") = 1, py::arg("mode") = "auto", py::arg("noise") = "auto",
             R"doc(What Session.preview would render with, as plain data (the keys of `atlas preview --export-scene`'s
scene.json): camera (position, look_at, up, fov_y_deg), sun (direction_to_sun, irradiance_rgb = 4 pi x
Atlas's sun colour), sky (zenith_rgb, horizon_rgb), phase (g_forward, g_back, forward_weight),
extinction_per_metre, width, height, artistic. A host sets its own renderer's camera and lights from it.)doc")
        .def("cook_requirements", [](PySession& ps, int jobs, const py::object& cache_dir, const py::object& memory_budget,
                                     const py::object& progress, const py::object& cancel) {
                 BusyGuard guard(ps);
                 CookOptions o = make_options(py::none(), jobs, true, py::none(), cache_dir, false, memory_budget, progress, cancel);
                 std::vector<std::pair<std::string, CookResult>> done;
                 {
                     py::gil_scoped_release nogil;
                     done = ps.session.cook_requirements(o);
                 }
                 py::list l;
                 for (const auto& [file, r] : done) l.append(py::make_tuple(file, result_to_python(r)));
                 return l;
             },
             py::arg("jobs") = 0, py::arg("cache_dir") = py::none(), py::arg("memory_budget") = py::none(),
             py::arg("progress") = py::none(), py::arg("cancel") = py::none(),
             R"doc(Cooks and writes every graph the loaded graph's `requires:` names whose output this graph reads
and is missing (into that requirement's `out` folder), as `atlas cook` does first. Returns a list of
(graph file, report dict) in cook order; [] when every input is there.)doc")
        .def("get", [](PySession& ps, const std::string& node, const py::object& port, int jobs, const py::object& cache_dir,
                       const py::object& memory_budget, const py::object& progress, const py::object& cancel, int proxy) {
                 BusyGuard guard(ps);
                 Session& s = ps.session;
                 std::string port_name = port.is_none() ? "" : port.cast<std::string>();
                 if (port_name.empty()) {
                     const GraphNode* n = s.graph().find(node);
                     const NodeType* t = n ? s.registry().find(n->type) : nullptr;
                     if (t && !t->decl.outputs().empty()) port_name = t->decl.outputs().front().name;
                 }
                 CookOptions o = make_options(py::none(), jobs, false, py::none(), cache_dir, false, memory_budget, progress, cancel);
                 o.proxy = proxy;
                 Value v;
                 {
                     py::gil_scoped_release nogil;
                     v = s.get(node, port_name, o);
                 }
                 return value_to_python(v);
             },
             py::arg("node"), py::arg("port") = py::none(), py::arg("jobs") = 0, py::arg("cache_dir") = py::none(),
             py::arg("memory_budget") = py::none(), py::arg("progress") = py::none(), py::arg("cancel") = py::none(), py::arg("proxy") = 1,
             "Cooks what one node output needs (port default: the node's first output; proxy as in cook) and returns it: an atlas.Field2D or "
             "Field3D (channels as read-only NumPy views), or for a mesh / points a dict of read-only arrays.")
        .def("nodes", [](PySession& ps) { BusyGuard guard(ps); return graph_nodes(ps.session); }, "The graph's nodes in file order: [{name, type, where, params (resolved), explicit, inputs}].")
        .def("outputs", [](PySession& ps) { BusyGuard guard(ps); return graph_outputs(ps.session); }, "The graph's outputs: [{node, port, file, format, options, where}].")
        .def("node_types", [](PySession& ps) {
                 BusyGuard guard(ps);
                 const Session& s = ps.session;
                 py::list l;
                 for (const NodeType* t : s.registry().all()) l.append(declaration_to_python(*t));
                 return l;
             }, "Every node type's declaration as plain data (see atlas.node_types()).")
        .def("declaration", [](PySession& ps, const std::string& type) {
                 BusyGuard guard(ps);
                 const Session& s = ps.session;
                 const NodeType* t = s.registry().find(type);
                 if (!t) throw Error("unknown node type '" + type + "'" + name_hint(type, s.registry().names()));
                 return declaration_to_python(*t);
             }, py::arg("type"), "One node type's declaration as plain data.")
        .def("node_hashes", [](PySession& ps) {
                 BusyGuard guard(ps);
                 const Session& s = ps.session;
                 std::map<std::string, std::string> out;
                 for (const auto& [name, h] : s.node_hashes()) out[name] = h.hex();
                 return out;
             }, "Each node's content hash (hex).")
        .def_property_readonly("file", [](PySession& ps) {
                 BusyGuard guard(ps);
                 const Session& s = ps.session; return s.graph().file.string(); }, "The graph file ('' when loaded from text).");
}
