// atlas/io/yaml_document.h: positions are the text's own (counted here from the string),
// header and key checks accept exactly what they say.
#include "atlas/io/yaml_document.h"

#include <gtest/gtest.h>

using namespace atlas;

namespace {

// 1-based line and column of the first occurrence of needle in text.
std::pair<int, int> position_of(const std::string& text, const std::string& needle) {
    const size_t at = text.find(needle);
    int line = 1, col = 1;
    for (size_t i = 0; i < at; ++i) {
        if (text[i] == '\n') ++line, col = 1;
        else ++col;
    }
    return {line, col};
}

template <class F>
ParseError parse_error(F&& f) {
    try {
        f();
    } catch (const ParseError& e) {
        return e;
    }
    ADD_FAILURE() << "no ParseError";
    return ParseError({}, "");
}

TEST(YamlDocument, LocationsAreOneBasedLineAndColumn) {
    const std::string text = "atlas_x: 1\nlist:\n  alpha: 2\n  beta: [1, 2]\n";
    const YAML::Node root = io::load_yaml(text, "f.yaml");
    const auto [l, c] = position_of(text, "beta");
    const YAML::Node list = root["list"];
    for (const auto& kv : list) {
        if (kv.first.Scalar() != "beta") continue;
        const SourceLocation at = io::yaml_location("f.yaml", kv.first);
        EXPECT_EQ(at.file, "f.yaml");
        EXPECT_EQ(at.line, l);
        EXPECT_EQ(at.column, c);
    }
    EXPECT_EQ(io::yaml_location("f.yaml", YAML::Node(3)).line, 0) << "a node built in code has no position";
}

TEST(YamlDocument, SyntaxErrorsAreParseErrorsWithThePrefix) {
    const std::string text = "a: 1\nb: [1, 2\n";
    const ParseError e = parse_error([&] { io::load_yaml(text, "bad.yaml", "invalid YAML: "); });
    EXPECT_EQ(e.where().file, "bad.yaml");
    EXPECT_GE(e.where().line, 2);
    EXPECT_EQ(e.detail().rfind("invalid YAML: ", 0), 0u) << e.detail();
}

TEST(YamlDocument, VersionedHeader) {
    auto check = [](const std::string& text) {
        io::require_versioned_map(io::load_yaml(text, "h.yaml"), "h.yaml", "atlas_thing", "1", "not a map", "bad version");
    };
    EXPECT_NO_THROW(check("atlas_thing: 1\nother: 2\n"));
    EXPECT_EQ(parse_error([&] { check("- 1\n- 2\n"); }).detail(), "not a map");
    EXPECT_EQ(parse_error([&] { check(""); }).detail(), "not a map");
    const ParseError missing = parse_error([&] { check("other: 2\n"); });
    EXPECT_EQ(missing.detail(), "bad version");
    EXPECT_EQ(missing.where().line, 1);
    const std::string two = "other: 2\natlas_thing: 2\n";
    const ParseError wrong = parse_error([&] { check(two); });
    EXPECT_EQ(wrong.detail(), "bad version");
    EXPECT_EQ(wrong.where().line, 2) << "points at the version value";
    EXPECT_EQ(wrong.where().column, position_of(two, "atlas_thing: 2").second + int(std::string("atlas_thing: ").size()));
}

TEST(YamlDocument, UnknownKeysAreNamedWithThePrefix) {
    const std::string text = "a: 1\nb: 2\nzz: 3\n";
    const YAML::Node root = io::load_yaml(text, "k.yaml");
    EXPECT_NO_THROW(io::reject_unknown_keys(root, "k.yaml", {"a", "b", "zz"}, "a, b, zz"));
    const ParseError e = parse_error([&] { io::reject_unknown_keys(root, "k.yaml", {"a", "b"}, "a, b", "thing: "); });
    EXPECT_EQ(e.detail(), "thing: unknown key 'zz' (expected a, b)");
    EXPECT_EQ(e.where().line, 3);
    EXPECT_EQ(e.where().column, 1);
}

} // namespace
