// Graph files: YAML text -> Graph, with every error located at file:line:col.
#include "atlas/graph/graph.h"

#include "atlas/core/files.h"
#include "atlas/io/writers.h"
#include "atlas/io/yaml_document.h"
#include "graph_walk.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

namespace atlas {

namespace {

struct Parser {
    std::string filename;

    SourceLocation at(const YAML::Node& n) const { return io::yaml_location(filename, n); }
    [[noreturn]] void fail(const YAML::Node& n, const std::string& msg) const { throw ParseError(at(n), msg); }

    std::string scalar(const YAML::Node& n, const std::string& what) const {
        if (!n.IsScalar()) fail(n, what + ": expected a string");
        return n.Scalar();
    }

    // Rejects keys not in `allowed`, with a did-you-mean.
    void check_keys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& where) const {
        std::set<std::string> seen;
        for (auto it = map.begin(); it != map.end(); ++it) {
            std::string key = scalar(it->first, where + " key");
            if (!seen.insert(key).second) fail(it->first, where + ": duplicate key '" + key + "'");
            if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
                fail(it->first, where + ": unknown key '" + key + "'" + name_hint(key, allowed));
            }
        }
    }
};

bool parse_bool(const std::string& s, bool& out) {
    if (s == "true" || s == "yes" || s == "on" || s == "1") { out = true; return true; }
    if (s == "false" || s == "no" || s == "off" || s == "0") { out = false; return true; }
    return false;
}

bool parse_int(const std::string& s, int64_t& out) {
    if (s.empty()) return false;
    size_t used = 0;
    try {
        long long v = std::stoll(s, &used, 10);
        if (used != s.size()) return false;
        out = v;
        return true;
    } catch (...) {
        return false;
    }
}

bool parse_double(const std::string& s, double& out) {
    if (s.empty()) return false;
    size_t used = 0;
    try {
        double v = std::stod(s, &used);
        if (used != s.size()) return false;
        out = v;
        return true;
    } catch (...) {
        return false;
    }
}

// Converts a YAML node to the declared type, or returns an error message.
std::string yaml_to_param(const YAML::Node& n, const ParamDecl& decl, ParamValue& out) {
    const int comps = param_components(decl.type);
    if (comps > 1) {
        if (!n.IsSequence()) return "expected a list of " + std::to_string(comps) + " numbers, e.g. [" + (comps == 2 ? "1, 2" : "1, 2, 3") + "]";
        std::vector<double> v;
        for (const auto& e : n) {
            double d;
            if (!e.IsScalar() || !parse_double(e.Scalar(), d)) return "expected numbers in the list";
            v.push_back(d);
        }
        out = v;
        return "";
    }
    if (decl.type == ParamType::String && decl.check_value && n.IsSequence()) {
        // A schema text option that takes numbers (sky_colour: [0.1, 0.2, 0.5]): its
        // comma-separated text, checked by the schema.
        std::string text;
        for (const auto& e : n) {
            if (!e.IsScalar()) return "expected numbers in the list";
            text += (text.empty() ? "" : ",") + e.Scalar();
        }
        out = text;
        return "";
    }
    if (!n.IsScalar()) return "expected a single " + std::string(param_type_name(decl.type)) + " value";
    const std::string& s = n.Scalar();
    switch (decl.type) {
    case ParamType::Float: {
        double d;
        if (!parse_double(s, d)) return "expected a number, got '" + s + "'";
        out = d;
        return "";
    }
    case ParamType::Int: {
        int64_t i;
        if (!parse_int(s, i)) return "expected an integer, got '" + s + "'";
        out = i;
        return "";
    }
    case ParamType::Bool: {
        bool b;
        if (!parse_bool(s, b)) return "expected true or false, got '" + s + "'";
        out = b;
        return "";
    }
    default:
        out = s;
        return "";
    }
}

void parse_inputs(const Parser& p, const YAML::Node& inputs, GraphNode& node) {
    if (!inputs.IsMap()) p.fail(inputs, "node '" + node.name + "': 'inputs' must be a map of input port to source node");
    for (auto it = inputs.begin(); it != inputs.end(); ++it) {
        std::string port = p.scalar(it->first, "input name");
        if (node.inputs.count(port)) p.fail(it->first, "node '" + node.name + "': input '" + port + "' given twice");
        InputBinding b;
        b.where = p.at(it->second);
        if (it->second.IsScalar()) {
            // "source" or "source.port"
            std::string s = it->second.Scalar();
            auto dot = s.find('.');
            b.node = s.substr(0, dot);
            if (dot != std::string::npos) b.port = s.substr(dot + 1);
        } else if (it->second.IsMap()) {
            p.check_keys(it->second, {"node", "port"}, "input '" + port + "'");
            if (!it->second["node"]) p.fail(it->second, "input '" + port + "': expected 'node'");
            b.node = p.scalar(it->second["node"], "input node");
            if (it->second["port"]) b.port = p.scalar(it->second["port"], "input port");
        } else {
            p.fail(it->second, "node '" + node.name + "': input '" + port + "' must name a node ('source' or 'source.port')");
        }
        if (b.node.empty()) p.fail(it->second, "node '" + node.name + "': input '" + port + "' names no node");
        node.inputs[port] = b;
    }
}

// A name as an error echoes it: at most 80 characters (a 10 MB string is
// not repeated back in full).
std::string excerpt(const std::string& s) {
    if (s.size() <= 80) return s;
    return s.substr(0, 60) + "... (" + std::to_string(s.size()) + " bytes)";
}

// "" when outputs a and b write different files; else how they collide.
std::string output_clash(const GraphOutput& a, const GraphOutput& b) {
    const std::string pa = std::filesystem::path(a.file).lexically_normal().generic_string();
    const std::string pb = std::filesystem::path(b.file).lexically_normal().generic_string();
    if (pa == pb) return a.file == b.file ? "is written twice: also by" : "names the same file as";
    // Files a multi-file output claims beside its name.
    auto claims = [](const GraphOutput& o, const std::string& stem, const std::string& name) {
        auto digits_between = [&](const std::string& pre, const std::string& post) {
            if (name.size() <= stem.size() + pre.size() + post.size() || name.rfind(stem + pre, 0) != 0) return false;
            if (name.compare(name.size() - post.size(), post.size(), post) != 0) return false;
            const std::string mid = name.substr(stem.size() + pre.size(), name.size() - stem.size() - pre.size() - post.size());
            return !mid.empty() && std::all_of(mid.begin(), mid.end(), [](unsigned char c) { return std::isdigit(c); });
        };
        if (o.format == "tga-slices") return digits_between(".", ".tga") || digits_between("(", ").tga");
        if (o.format == "vdb-sequence") return digits_between(".", ".vdb");
        if (o.format == "dds") return name == stem + ".json";
        return false;
    };
    if (claims(a, pa, pb) || claims(b, pb, pa)) return "collides with a file written by";
    return "";
}

// The output's format exists, accepts what the port produces, and knows its options.
void check_output_request(PortType produced, const std::string& format, const std::map<std::string, std::string>& options) {
    const io::OutputFormat* fmt = nullptr;
    std::vector<std::string> names;
    for (const auto& f : io::output_formats()) {
        names.push_back(f.name);
        if (f.name == format) fmt = &f;
    }
    if (!fmt) {
        throw Error("unknown format '" + format + "'" + name_hint(format, names, "known"));
    }
    bool ok = false;
    for (PortType t : fmt->accepts) ok = ok || port_accepts(t, produced) || port_accepts(produced, t);
    if (!ok) {
        std::string acc;
        for (PortType t : fmt->accepts) acc += (acc.empty() ? "" : " or ") + std::string(port_type_name(t));
        throw Error("format '" + format + "' writes " + acc + ", but the port produces a " + std::string(port_type_name(produced)));
    }
    std::vector<std::string> known;
    for (const auto& o : fmt->options) known.push_back(o.first);
    for (const auto& kv : options) {
        if (std::find(known.begin(), known.end(), kv.first) != known.end()) continue;
        throw Error("unknown option '" + kv.first + "' for format '" + format + "'" + name_hint(kv.first, known, "known"));
    }
}

// `{keys: [[t, v], ...], interp: linear|smooth}` for a numeric parameter.
ParamKeys parse_keys(const Parser& p, const YAML::Node& n, const ParamDecl& decl, const std::string& what) {
    p.check_keys(n, {"keys", "interp"}, "keyed parameter");
    switch (decl.type) {
    case ParamType::Float: case ParamType::Int: case ParamType::Float2: case ParamType::Float3: case ParamType::Int2: case ParamType::Int3: break;
    default: p.fail(n, what + "only numbers can be keyed over time; give a plain value");
    }
    ParamKeys k;
    k.where = p.at(n);
    if (const YAML::Node in = n["interp"]) {
        const std::string s = p.scalar(in, "interp");
        if (s != "linear" && s != "smooth") p.fail(in, what + "interp must be 'linear' or 'smooth', got '" + excerpt(s) + "'");
        k.smooth = s == "smooth";
    }
    const YAML::Node keys = n["keys"];
    if (!keys || !keys.IsSequence() || keys.size() == 0)
        p.fail(keys ? keys : n, what + "keys must be a list of [time, value] pairs, e.g. keys: [[0, 0.2], [120, 0.8]]");
    for (const YAML::Node& key : keys) {
        if (!key.IsSequence() || key.size() != 2) p.fail(key, what + "a key is [time, value], e.g. [120, 0.8]");
        double t = 0;
        try {
            t = key[0].as<double>();
        } catch (const YAML::Exception&) {
            p.fail(key[0], what + "a key's time must be a number of seconds");
        }
        if (!std::isfinite(t)) p.fail(key[0], what + "a key's time must be finite");
        if (!k.keys.empty() && !(t > k.keys.back().first))
            p.fail(key[0], what + "key times must increase: " + format_param_value(t) + " follows " + format_param_value(k.keys.back().first));
        ParamValue v;
        std::string err = yaml_to_param(key[1], decl, v);
        if (err.empty()) err = decl.check(v);
        if (!err.empty()) p.fail(key[1], what + "the key at " + format_param_value(t) + " s: " + err);
        k.keys.emplace_back(t, v);
    }
    return k;
}

} // namespace

std::string detail::param_from_yaml(const YAML::Node& n, const ParamDecl& decl, ParamValue& out) { return yaml_to_param(n, decl, out); }

std::string closest_match(const std::string& word, const std::vector<std::string>& candidates) {
    auto distance = [](const std::string& a, const std::string& b) {
        std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
        for (size_t i = 1; i <= a.size(); ++i) {
            cur[0] = i;
            for (size_t j = 1; j <= b.size(); ++j)
                cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            std::swap(prev, cur);
        }
        return prev[b.size()];
    };
    // The distance is at least the length difference: a candidate that far
    // off is not measured (a 10 MB word costs nothing, not a minute).
    auto far = [](const std::string& a, const std::string& b, size_t limit) {
        return (a.size() > b.size() ? a.size() - b.size() : b.size() - a.size()) >= limit;
    };
    std::string best;
    size_t best_d = std::max<size_t>(2, word.size() / 3) + 1;
    if (word.size() > 256) return best; // no name is that long
    for (const auto& c : candidates) {
        size_t d = far(word, c, best_d) ? best_d : distance(word, c);
        // Also accept a candidate whose last path component matches ("perlin" -> "noise/perlin").
        auto slash = c.rfind('/');
        if (slash != std::string::npos && !far(word, c.substr(slash + 1), best_d)) d = std::min(d, distance(word, c.substr(slash + 1)) + 1);
        if (d < best_d) { best_d = d; best = c; }
    }
    return best;
}

std::string name_hint(const std::string& word, const std::vector<std::string>& candidates, const std::string& intro) {
    if (auto s = closest_match(word, candidates); !s.empty()) return " (did you mean '" + s + "'?)";
    if (candidates.empty()) return "";
    // Long lists (every node type) are cut: a message is not a manual.
    constexpr size_t kMaxListed = 12;
    std::string list;
    for (size_t i = 0; i < candidates.size() && i < kMaxListed; ++i) list += (list.empty() ? "" : ", ") + candidates[i];
    if (candidates.size() > kMaxListed) list += ", and " + std::to_string(candidates.size() - kMaxListed) + " more";
    return " (" + intro + ": " + list + ")";
}

const GraphNode* Graph::find(const std::string& name) const {
    for (const auto& n : nodes) if (n.name == name) return &n;
    return nullptr;
}
GraphNode* Graph::find(const std::string& name) {
    for (auto& n : nodes) if (n.name == name) return &n;
    return nullptr;
}

Graph parse_graph(const std::string& text, const std::string& filename, const std::filesystem::path& base_dir,
                  const NodeRegistry& registry) {
    Parser p{filename};
    const YAML::Node root = io::load_yaml(text, filename, "invalid YAML: ");
    if (!root || root.IsNull()) throw ParseError({filename, 1, 1}, "empty graph file: expected 'atlas: 1', 'nodes' and 'outputs'");
    if (!root.IsMap()) p.fail(root, "a graph file is a map with 'atlas', 'nodes' and 'outputs'");
    p.check_keys(root, {"atlas", "description", "requires", "budget", "time", "nodes", "outputs"}, "graph");

    Graph g;
    g.base_dir = base_dir;
    if (!root["atlas"]) p.fail(root, "missing 'atlas: " + std::to_string(kGraphFormatVersion) + "' version line");
    {
        int64_t v = 0;
        const YAML::Node vn = root["atlas"];
        if (!vn.IsScalar() || !parse_int(vn.Scalar(), v)) p.fail(vn, "'atlas' must be the format version number, e.g. atlas: 1");
        if (v != kGraphFormatVersion)
            p.fail(vn, "unsupported graph format version " + std::to_string(v) + " (this Atlas reads version " +
                           std::to_string(kGraphFormatVersion) + ")");
        g.version = int(v);
    }

    if (const YAML::Node req = root["requires"]) {
        if (!req.IsSequence()) p.fail(req, "'requires' must be a list of {graph, out}: graphs whose outputs this graph reads");
        for (const auto& r : req) {
            if (!r.IsMap()) p.fail(r, "a requirement is a map {graph: FILE.yaml, out: FOLDER} (both relative to this graph)");
            p.check_keys(r, {"graph", "out"}, "requirement");
            if (!r["graph"]) p.fail(r, "requirement: missing 'graph' (the graph file that writes what this graph reads)");
            if (!r["out"]) p.fail(r, "requirement: missing 'out' (the folder that graph's cook writes, which this graph reads)");
            GraphRequirement gr;
            gr.where = p.at(r);
            gr.graph = (base_dir / p.scalar(r["graph"], "requirement graph")).lexically_normal();
            gr.out = (base_dir / p.scalar(r["out"], "requirement out")).lexically_normal();
            if (gr.graph.empty() || gr.out.empty() || gr.out == base_dir.lexically_normal())
                p.fail(r, "requirement: 'out' must name a folder of its own, not this graph's folder");
            g.requirements.push_back(std::move(gr));
        }
    }

    if (const YAML::Node b = root["budget"]) {
        if (!b.IsMap()) p.fail(b, "'budget' is a map, e.g. budget: {texture_mb: 25}");
        p.check_keys(b, {"texture_mb"}, "budget");
        if (const YAML::Node t = b["texture_mb"]) {
            double mb = 0;
            if (!t.IsScalar() || !parse_double(t.Scalar(), mb) || !std::isfinite(mb) || mb <= 0)
                p.fail(t, "budget: texture_mb must be a positive number of megabytes (10^6 bytes of DDS texture data), got '" +
                              (t.IsScalar() ? t.Scalar() : std::string("a list or map")) + "'");
            g.texture_budget_mb = mb;
            g.budget_where = p.at(t);
        }
    }
    if (const YAML::Node tn = root["time"]) {
        if (!tn.IsMap()) p.fail(tn, "'time' is a map, e.g. time: {start: 0, end: 300, fps: 1} (seconds, frames per second)");
        p.check_keys(tn, {"start", "end", "fps"}, "time");
        GraphTime gt;
        gt.where = p.at(tn);
        auto number = [&](const char* key, double fallback) {
            const YAML::Node v = tn[key];
            if (!v) return fallback;
            double x = 0;
            try {
                x = v.as<double>();
            } catch (const YAML::Exception&) {
                p.fail(v, std::string("time: ") + key + " must be a number of seconds" + (std::string(key) == "fps" ? " (frames per second)" : ""));
            }
            if (!std::isfinite(x)) p.fail(v, std::string("time: ") + key + " must be finite");
            return x;
        };
        gt.start = number("start", 0);
        if (!tn["end"]) p.fail(tn, "time: 'end' is required (the last frame's time in seconds)");
        gt.end = number("end", 0);
        gt.fps = number("fps", 1);
        if (!(gt.end >= gt.start)) p.fail(tn["end"], "time: end must not be before start");
        if (!(gt.fps > 0 && gt.fps <= 1000)) p.fail(tn["fps"] ? tn["fps"] : tn, "time: fps must be in (0, 1000]");
        if ((gt.end - gt.start) * gt.fps > 1e6) p.fail(tn, "time: more than a million frames");
        g.time = gt;
        g.current_time = gt.start;
    }

    const YAML::Node nodes = root["nodes"];
    if (!nodes) p.fail(root, "missing 'nodes' map");
    if (!nodes.IsMap()) p.fail(nodes, "'nodes' must be a map of node name to node");
    const auto type_names = registry.names();
    for (auto it = nodes.begin(); it != nodes.end(); ++it) {
        GraphNode n;
        n.name = p.scalar(it->first, "node name");
        n.where = p.at(it->first);
        if (n.name.empty() || n.name.find_first_of(". \t") != std::string::npos)
            p.fail(it->first, "node name '" + n.name + "' may not be empty or contain '.' or spaces");
        if (g.find(n.name)) p.fail(it->first, "duplicate node name '" + n.name + "'");
        const YAML::Node body = it->second;
        if (!body.IsMap()) p.fail(body, "node '" + n.name + "': expected a map with 'type', 'params' and 'inputs'");
        p.check_keys(body, {"type", "params", "inputs", "doc"}, "node '" + n.name + "'");
        if (!body["type"]) p.fail(body, "node '" + n.name + "': missing 'type'");
        n.type = p.scalar(body["type"], "node type");
        const NodeType* type = registry.find(n.type);
        if (!type) {
            std::string hint = closest_match(n.type, type_names);
            p.fail(body["type"], "node '" + n.name + "': unknown node type '" + excerpt(n.type) + "'" +
                                     (hint.empty() ? " (run 'atlas nodes' for the list)" : " (did you mean '" + hint + "'?)"));
        }
        if (const YAML::Node params = body["params"]) {
            if (!params.IsMap()) p.fail(params, "node '" + n.name + "': 'params' must be a map");
            std::vector<std::string> known;
            for (const auto& d : type->decl.params()) known.push_back(d.name);
            for (auto pit = params.begin(); pit != params.end(); ++pit) {
                std::string pname = p.scalar(pit->first, "parameter name");
                const ParamDecl* decl = type->decl.find_param(pname);
                if (!decl) {
                    p.fail(pit->first, "node '" + n.name + "': unknown parameter '" + pname + "'" +
                                           (known.empty() ? " (" + n.type + " has no parameters)" : name_hint(pname, known, n.type + " has")));
                }
                if (n.params.count(pname)) p.fail(pit->first, "node '" + n.name + "': parameter '" + pname + "' given twice");
                ParamValue v;
                const std::string what = "node '" + n.name + "': parameter '" + pname + "' (" + std::string(param_type_name(decl->type)) + "): ";
                if (pit->second.IsMap()) {
                    // Keyed over time: {keys: [[t, v], ...], interp: linear|smooth}.
                    n.keyed[pname] = parse_keys(p, pit->second, *decl, what);
                    v = keyed_value(n.keyed[pname], *decl, g.current_time);
                    n.params[pname] = {v, p.at(pit->second)};
                    continue;
                }
                std::string err = yaml_to_param(pit->second, *decl, v);
                if (err.empty()) err = decl->check(v);
                if (!err.empty()) p.fail(pit->second, what + err);
                n.params[pname] = {v, p.at(pit->second)};
            }
        }
        if (const YAML::Node inputs = body["inputs"]) parse_inputs(p, inputs, n);
        g.nodes.push_back(std::move(n));
    }

    const YAML::Node outputs = root["outputs"];
    if (!outputs) p.fail(root, "missing 'outputs' list (what the graph writes)");
    if (!outputs.IsSequence()) p.fail(outputs, "'outputs' must be a list of {node, port, file, format}");
    for (const auto& o : outputs) {
        if (!o.IsMap()) p.fail(o, "an output is a map with 'node', 'file' and optionally 'port', 'format', 'options'");
        p.check_keys(o, {"node", "port", "file", "format", "options"}, "output");
        GraphOutput out;
        out.where = p.at(o);
        if (!o["node"]) p.fail(o, "output: missing 'node'");
        if (!o["file"]) p.fail(o, "output: missing 'file'");
        out.node = p.scalar(o["node"], "output node");
        out.file = p.scalar(o["file"], "output file");
        try {
            check_output_name(out.file);
        } catch (const Error& e) {
            p.fail(o["file"], e.what());
        }
        if (o["port"]) out.port = p.scalar(o["port"], "output port");
        if (o["format"]) out.format = p.scalar(o["format"], "output format");
        if (const YAML::Node opts = o["options"]) {
            if (!opts.IsMap()) p.fail(opts, "output '" + out.file + "': 'options' must be a map");
            for (auto it = opts.begin(); it != opts.end(); ++it) {
                std::string v;
                if (it->second.IsSequence()) {
                    for (const auto& e : it->second) v += (v.empty() ? "" : ",") + p.scalar(e, "option value");
                } else {
                    v = p.scalar(it->second, "option value");
                }
                out.options[p.scalar(it->first, "option name")] = v;
            }
        }
        // Output-level checks that need the source location.
        const GraphNode* src = g.find(out.node);
        if (!src) {
            std::vector<std::string> names;
            for (const auto& n : g.nodes) names.push_back(n.name);
            p.fail(o["node"], "output '" + out.file + "': unknown node '" + out.node + "'" + name_hint(out.node, names, "nodes"));
        }
        const NodeType* st = registry.find(src->type);
        if (out.port.empty()) {
            if (st->decl.outputs().size() != 1) {
                std::string list;
                for (const auto& po : st->decl.outputs()) list += (list.empty() ? "" : ", ") + po.name;
                p.fail(o, "output '" + out.file + "': node '" + out.node + "' has several outputs (" + list + "); say which with 'port'");
            }
            out.port = st->decl.outputs().front().name;
        }
        const PortDecl* port = st->decl.find_output(out.port);
        if (!port) {
            std::vector<std::string> names;
            for (const auto& po : st->decl.outputs()) names.push_back(po.name);
            p.fail(o["port"] ? o["port"] : o, "output '" + out.file + "': node '" + out.node + "' (" + src->type +
                                                  ") has no output port '" + out.port + "'" + name_hint(out.port, names, "it has"));
        }
        try {
            if (out.format.empty()) out.format = io::output_format_for_path(out.file);
            check_output_request(port->type, out.format, out.options);
        } catch (const ParseError&) {
            throw;
        } catch (const Error& e) {
            const std::string msg = e.what();
            p.fail(o, msg.rfind("output '", 0) == 0 ? msg : "output '" + out.file + "': " + msg);
        }
        // An explicit format that the file's extension contradicts (format: png on a .exr name).
        if (o["format"]) {
            std::string by_name;
            try {
                by_name = io::output_format_for_path(out.file);
            } catch (const Error&) {
                // no known extension: a stem (tga-slices, vdb-sequence) or a custom name
            }
            if (!by_name.empty() && by_name != out.format)
                p.fail(o["format"], "output '" + out.file + "': format '" + out.format + "' contradicts the file name's extension (a '" + by_name +
                                        "' file)" + (out.format == "tga-slices" || out.format == "vdb-sequence"
                                                         ? "; format '" + out.format + "' takes DIR/STEM without an extension"
                                                         : "; rename the file or drop 'format'"));
        }
        // Option values, as the writer will parse them: a bad one is refused
        // here, with the option's file:line, not after cooking everything.
        try {
            io::check_output_options(out.format, out.file, out.options, port->type);
        } catch (const Error& e) {
            const std::string msg = e.what();
            const std::string tail = msg.rfind("output '", 0) == 0 ? msg.substr(msg.find("': ") + 3) : msg;
            const YAML::Node opts = o["options"];
            SourceLocation at = p.at(opts ? opts : o);
            for (const auto& kv : out.options)
                if (tail.find("option '" + kv.first + "'") != std::string::npos || tail.find("options '" + kv.first + "'") != std::string::npos) {
                    at = p.at(opts[kv.first]);
                    break;
                }
            throw ParseError(at, "output '" + out.file + "': " + tail);
        }
        // Two outputs may not name the same file, however spelled (./v.exr,
        // x/../v.exr, d//v.exr), nor a file another output writes beside its
        // own (a slice stack's STEM.001.tga, a DDS manifest).
        for (const auto& prev : g.outputs)
            if (const std::string clash = output_clash(prev, out); !clash.empty())
                p.fail(o, "output '" + out.file + "' " + clash + " output '" + prev.file + "' (" + prev.where.str() + ")");
        g.outputs.push_back(std::move(out));
    }

    validate_graph(g, registry);
    return g;
}

Graph load_graph(const std::filesystem::path& file, const NodeRegistry& registry) {
    std::string text;
    try {
        text = read_file_bytes(file);
    } catch (const Error& e) {
        std::error_code ec;
        if (std::filesystem::exists(file, ec)) throw Error(std::string(e.what()) + " (the graph file)");
        throw Error(file.string() + ": cannot read graph file (does it exist?)");
    }
    Graph g = parse_graph(text, file.string(), file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path(), registry);
    g.file = file;
    return g;
}

} // namespace atlas
