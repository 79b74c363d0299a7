// atlas/io/yaml_document.h - the one YAML preamble of the library's text formats (graph
// files, weather presets, forecasts): parse a document, turn yaml-cpp's marks into
// file:line:column, check the versioned header ("atlas: 1", "atlas_presets: 1", ...) and
// the top-level keys. Errors are atlas::ParseError naming the file, line and column.
// Thread-safe (no shared state).
#pragma once

#include "atlas/core/error.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace atlas::io {

// Where n sits in `filename`: 1-based line and column, or line 0 when n carries no mark
// (a node built in code rather than parsed).
SourceLocation yaml_location(const std::string& filename, const YAML::Node& n);

// Parses text as one YAML document. A syntax error is a ParseError at its line:column
// (0:0 when yaml-cpp gives none) with the message error_prefix + yaml-cpp's message.
YAML::Node load_yaml(const std::string& text, const std::string& filename, const std::string& error_prefix = "");

// A versioned Atlas document: root must be a map (else ParseError at 1:1 with not_a_map),
// and root[key] the scalar `version` (else ParseError at that value, or at 1:1 when the key
// is missing, with bad_version).
void require_versioned_map(const YAML::Node& root, const std::string& filename, const std::string& key, const std::string& version,
                           const std::string& not_a_map, const std::string& bad_version);

// Every key of `map` must be in `allowed`; otherwise ParseError at the key:
// prefix + "unknown key 'K' (expected " + expected + ")".
void reject_unknown_keys(const YAML::Node& map, const std::string& filename, const std::vector<std::string>& allowed,
                         const std::string& expected, const std::string& prefix = "");

} // namespace atlas::io
