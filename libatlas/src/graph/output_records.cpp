#include "output_records.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <fstream>

namespace atlas {

namespace {
std::map<std::string, OutputRecord> read_records(const std::filesystem::path& file) {
    std::map<std::string, OutputRecord> out;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) return out;
    try {
        const auto j = nlohmann::json::parse(read_file_bytes(file));
        if (j.value("atlas_outputs_version", 0) != 1) return out;
        for (const auto& [name, r] : j.at("outputs").items()) {
            OutputRecord rec;
            rec.key = r.at("key").get<std::string>();
            rec.spec = r.value("spec", "");
            rec.value_hash = r.value("value_hash", "");
            for (const auto& f : r.at("files"))
                rec.files.push_back({f.at("path").get<std::string>(), f.at("bytes").get<uint64_t>(), f.at("mtime_ns").get<int64_t>(),
                                     f.at("hash").get<std::string>()});
            for (const auto& [k, v] : r.at("metrics").items()) rec.metrics[k] = v.is_number() ? v.get<double>() : std::nan("");
            out[name] = std::move(rec);
        }
    } catch (const std::exception&) {
        return {}; // a damaged record file only costs a rewrite
    }
    return out;
}
} // namespace

int64_t file_mtime_ns(const std::filesystem::path& p) {
    std::error_code ec;
    const auto t = std::filesystem::last_write_time(p, ec);
    if (ec) return 0;
    // Unix time, as other tools read it (the file clock's own epoch is libstdc++'s, 2174).
    const auto sys = std::chrono::file_clock::to_sys(t);
    return int64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(sys.time_since_epoch()).count());
}

OutputRecords::OutputRecords(std::filesystem::path root) : root_(std::move(root)), records_(read_records(root_ / kFileName)) {}

const OutputRecord* OutputRecords::current(const std::string& name, const std::string& key) {
    auto it = records_.find(name);
    if (it == records_.end() || it->second.key != key) return nullptr;
    return on_disk(name);
}

bool files_unchanged(const std::filesystem::path& root, std::vector<OutputFileRecord>& files, bool* refreshed) {
    for (auto& f : files) {
        const std::filesystem::path p = root / f.path;
        std::error_code ec;
        if (!std::filesystem::is_regular_file(p, ec) || std::filesystem::file_size(p, ec) != f.bytes || ec) return false;
        const int64_t m = file_mtime_ns(p);
        if (m == f.mtime_ns) continue;
        // Touched or copied: the bytes decide.
        try {
            if (file_content_hash(p).hex() != f.hash) return false;
        } catch (const Error&) {
            return false;
        }
        f.mtime_ns = m;
        if (refreshed) *refreshed = true;
    }
    return true;
}

const OutputRecord* OutputRecords::on_disk(const std::string& name) {
    auto it = records_.find(name);
    if (it == records_.end() || it->second.files.empty()) return nullptr;
    OutputRecord& r = it->second;
    bool refreshed = false;
    if (!files_unchanged(root_, r.files, &refreshed)) return nullptr;
    if (refreshed) updates_[name] = r;
    return &r;
}

const OutputRecord* OutputRecords::find(const std::string& name) const {
    const auto it = records_.find(name);
    return it == records_.end() ? nullptr : &it->second;
}

void OutputRecords::set(const std::string& name, OutputRecord record) {
    records_[name] = record;
    updates_[name] = std::move(record);
}

void OutputRecords::save() {
    if (updates_.empty()) return;
    auto merged = read_records(root_ / kFileName);
    for (const auto& [name, r] : updates_) merged[name] = r;
    nlohmann::json outs = nlohmann::json::object();
    for (const auto& [name, r] : merged) {
        nlohmann::json files = nlohmann::json::array();
        for (const auto& f : r.files) files.push_back({{"path", f.path}, {"bytes", f.bytes}, {"mtime_ns", f.mtime_ns}, {"hash", f.hash}});
        nlohmann::json m = nlohmann::json::object();
        for (const auto& [k, v] : r.metrics) m[k] = std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
        outs[name] = {{"key", r.key}, {"spec", r.spec}, {"value_hash", r.value_hash}, {"files", files}, {"metrics", m}};
    }
    const std::string text = nlohmann::json{{"atlas_outputs_version", 1}, {"outputs", outs}}.dump(1) + "\n";
    write_file_atomic(root_ / kFileName, [&](const std::filesystem::path& tmp) { write_file_checked(tmp, text.data(), text.size()); });
    updates_.clear();
}

} // namespace atlas
