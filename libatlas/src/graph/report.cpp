// The --report JSON document. Build tools parse it: keep keys stable and
// documented in docs/report.md.
#include "atlas/graph/evaluator.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace atlas {

std::string CookResult::to_json(const std::string& graph_file) const {
    using nlohmann::json;
    json doc;
    doc["atlas_report_version"] = 1;
    doc["graph"] = graph_file;
    doc["seconds"] = seconds;
    doc["jobs"] = jobs;
    doc["checked"] = checked;
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
        json om = json::object();
        for (const auto& [k, v] : o.metrics) om[k] = std::isfinite(v) ? json(v) : json(nullptr);
        jo["metrics"] = om;
        outs.push_back(jo);
    }
    doc["outputs"] = outs;
    json summary;
    summary["cooked"] = with_status("cooked").size();
    summary["cached"] = with_status("cached").size();
    summary["skipped"] = with_status("skipped").size();
    doc["summary"] = summary;
    return doc.dump(2) + "\n";
}

} // namespace atlas
