// The shared YAML preamble (see atlas/io/yaml_document.h).
#include "atlas/io/yaml_document.h"

#include <algorithm>
#include <string_view>

namespace atlas::io {

SourceLocation yaml_location(const std::string& filename, const YAML::Node& n) {
    const YAML::Mark m = n.Mark();
    if (m.is_null()) return {filename, 0, 0};
    return {filename, m.line + 1, m.column + 1};
}

namespace {
// yaml-cpp keeps about 230 bytes per nesting level ("[[[[..." or "- - - ...")
// and recurses on them: a deeply nested file of a few MB took gigabytes.
// No Atlas document nests more than a handful of levels; 64 is refused first.
constexpr int kMaxNesting = 64;

void check_nesting(const std::string& text, const std::string& filename, const std::string& error_prefix) {
    int flow = 0, line = 1, col = 0;
    char quote = 0;
    bool comment = false, line_start = true;
    int dashes = 0;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        ++col;
        if (c == '\n') {
            ++line, col = 0, comment = false, line_start = true, dashes = 0;
            if (quote == '\'') quote = 0; // a broken quote ends with its line here; yaml-cpp reports it
            continue;
        }
        if (comment) continue;
        if (quote) {
            if (c == '\\' && quote == '"') ++i;
            else if (c == quote) quote = 0;
            continue;
        }
        if (line_start) {
            // "- - - x": each dash at the start of a line opens a sequence.
            if (c == '-' && i + 1 < text.size() && (text[i + 1] == ' ' || text[i + 1] == '\n')) {
                if (++dashes > kMaxNesting)
                    throw ParseError({filename, line, col}, error_prefix + "nested more than " + std::to_string(kMaxNesting) + " levels deep");
                continue;
            }
            if (c != ' ' && c != '\t') line_start = false;
        }
        if (c == '#') comment = true;
        else if ((c == '"' || c == '\'') && (i == 0 || std::string_view(" \t[{,:").find(text[i - 1]) != std::string_view::npos))
            quote = c; // a quote opens a quoted scalar only where one can start ("it's" is plain text)
        else if (c == '[' || c == '{') {
            if (++flow > kMaxNesting)
                throw ParseError({filename, line, col}, error_prefix + "nested more than " + std::to_string(kMaxNesting) + " levels deep");
        } else if ((c == ']' || c == '}') && flow > 0) --flow;
    }
}
} // namespace

YAML::Node load_yaml(const std::string& text, const std::string& filename, const std::string& error_prefix) {
    check_nesting(text, filename, error_prefix);
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
