// The shared YAML preamble (see atlas/io/yaml_document.h).
#include "atlas/io/yaml_document.h"

#include <algorithm>

namespace atlas::io {

SourceLocation yaml_location(const std::string& filename, const YAML::Node& n) {
    const YAML::Mark m = n.Mark();
    if (m.is_null()) return {filename, 0, 0};
    return {filename, m.line + 1, m.column + 1};
}

YAML::Node load_yaml(const std::string& text, const std::string& filename, const std::string& error_prefix) {
    try {
        return YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw ParseError({filename, e.mark.is_null() ? 0 : e.mark.line + 1, e.mark.is_null() ? 0 : e.mark.column + 1}, error_prefix + e.msg);
    }
}

void require_versioned_map(const YAML::Node& root, const std::string& filename, const std::string& key, const std::string& version,
                           const std::string& not_a_map, const std::string& bad_version) {
    if (!root || !root.IsMap()) throw ParseError({filename, 1, 1}, not_a_map);
    const YAML::Node v = root[key];
    if (!v || !v.IsScalar() || v.Scalar() != version)
        throw ParseError(v ? yaml_location(filename, v) : SourceLocation{filename, 1, 1}, bad_version);
}

void reject_unknown_keys(const YAML::Node& map, const std::string& filename, const std::vector<std::string>& allowed,
                         const std::string& expected, const std::string& prefix) {
    for (const auto& kv : map) {
        const std::string key = kv.first.Scalar();
        if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
            throw ParseError(yaml_location(filename, kv.first), prefix + "unknown key '" + key + "' (expected " + expected + ")");
    }
}

} // namespace atlas::io
