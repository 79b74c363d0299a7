// The --report JSON document. Build tools parse it: keep keys stable and
// documented in docs/report.md.
#include "atlas/graph/evaluator.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace atlas {

namespace {
nlohmann::json report_doc(const CookResult& r, const std::string& graph_file);
} // namespace

std::string CookResult::to_json(const std::string& graph_file) const { return report_doc(*this, graph_file).dump(2) + "\n"; }

std::string combined_report_json(const std::vector<std::pair<std::string, CookResult>>& cooks) {
    using nlohmann::json;
    json doc;
    doc["atlas_report_version"] = 1;
    std::string status = "ok";
    double seconds = 0;
    json graphs = json::array();
    json summary{{"cooked", 0}, {"cached", 0}, {"skipped", 0}};
    for (const auto& [file, r] : cooks) {
        graphs.push_back(report_doc(r, file));
        if (r.status != "ok" && status == "ok") status = r.status;
        seconds += r.seconds;
        for (const char* k : {"cooked", "cached", "skipped"}) summary[k] = summary[k].get<size_t>() + r.with_status(k).size();
    }
    doc["status"] = status;
    doc["seconds"] = seconds;
    doc["graphs"] = graphs;
    doc["summary"] = summary;
    return doc.dump(2) + "\n";
}

namespace {
nlohmann::json report_doc(const CookResult& self, const std::string& graph_file) {
    using nlohmann::json;
    const CookResult& cr = self;
    const auto& nodes = cr.nodes;
    const auto& outputs = cr.outputs;
    json doc;
    doc["atlas_report_version"] = 1;
    doc["graph"] = graph_file;
    doc["status"] = cr.status;
    if (cr.status != "ok") {
        json e{{"message", cr.error}};
        if (!cr.error_node.empty()) e["node"] = cr.error_node;
        if (!cr.error_output.empty()) e["output"] = cr.error_output;
        if (!cr.error_where.empty()) e["where"] = cr.error_where;
        doc["error"] = e;
    }
    const double seconds = cr.seconds;
    const int jobs = cr.jobs;
    const bool checked = cr.checked;
    doc["seconds"] = seconds;
    doc["jobs"] = jobs;
    doc["checked"] = checked;
    if (cr.proxy > 1) doc["proxy"] = cr.proxy;
    if (cr.memory_budget) doc["memory"] = json{{"budget", cr.memory_budget}, {"peak_counted", cr.memory_peak}};
    json jn = json::object();
    for (const auto& [name, r] : nodes) {
        json n;
        n["type"] = r.type;
        n["status"] = r.status;
        if (!r.reason.empty()) n["reason"] = r.reason;
        if (!r.hash.empty()) n["hash"] = r.hash;
        n["seconds"] = r.seconds;
        n["bytes"] = r.bytes;
        json m = json::object();
        for (const auto& [k, v] : r.metrics) m[k] = std::isfinite(v) ? json(v) : json(nullptr);
        n["metrics"] = m;
        if (!r.warnings.empty()) n["warnings"] = r.warnings;
        jn[name] = n;
    }
    doc["nodes"] = jn;
    json outs = json::array();
    for (const auto& o : outputs) {
        json jo{{"node", o.node}, {"port", o.port}, {"file", o.file}, {"format", o.format}};
        json files = json::array();
        for (const auto& p : o.written) files.push_back(p.string());
        jo["written"] = files;
        if (!o.status.empty()) jo["status"] = o.status;
        if (!o.error.empty()) jo["error"] = o.error;
        if (const uint64_t tb = o.texture_bytes()) jo["texture_bytes"] = tb;
        jo["seconds"] = o.seconds;
        json all = json::array();
        for (const auto& f : o.files) all.push_back({{"path", f.path.string()}, {"bytes", f.bytes}, {"hash", f.hash}});
        jo["files"] = all;
        json om = json::object();
        for (const auto& [k, v] : o.metrics) om[k] = std::isfinite(v) ? json(v) : json(nullptr);
        jo["metrics"] = om;
        outs.push_back(jo);
    }
    doc["outputs"] = outs;
    // GPU texture memory of the DDS outputs, against the graph's budget when it has one.
    const uint64_t texture_total = cr.texture_bytes();
    json tex{{"bytes", texture_total}};
    if (cr.texture_budget_mb) {
        tex["budget_mb"] = *cr.texture_budget_mb;
        tex["within_budget"] = double(texture_total) <= *cr.texture_budget_mb * 1e6;
    }
    doc["textures"] = tex;
    json ins = json::array();
    for (const auto& in : cr.inputs) ins.push_back({{"path", in.path.string()}, {"bytes", in.bytes}, {"hash", in.hash}, {"node", in.node}});
    doc["inputs"] = ins;
    json deps = json::array();
    for (const auto& p : cr.depends(graph_file)) deps.push_back(p.string());
    doc["depends"] = deps;
    doc["warnings"] = cr.warnings;
    json summary;
    summary["cooked"] = self.with_status("cooked").size();
    summary["cached"] = self.with_status("cached").size();
    summary["skipped"] = self.with_status("skipped").size();
    doc["summary"] = summary;
    return doc;
}
} // namespace

} // namespace atlas
