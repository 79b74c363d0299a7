// atlas/graph/node_docs.h - the node reference, generated from declarations.
// `atlas nodes` prints it and docs/nodes.md is this Markdown, so the docs
// cannot drift from the code (a test compares them).
#pragma once

#include "atlas/graph/node.h"

#include <string>

namespace atlas {

// Why a node type without a tiling rule (TileRule::Kind::None) is not cooked in tiles: its
// rule's own reason, else, for a node that makes only points or a mesh, that the nodes reading
// it take it whole (so it needs no rule). What `atlas nodes` shows and a tiled cook refuses with.
std::string tiling_refusal(const NodeDeclaration& decl);

// One line per node type: "name  summary".
std::string node_list_text(const NodeRegistry& registry);
// Ports and parameters of one node type, as plain text for a terminal.
std::string node_reference_text(const NodeType& type);
// The whole reference as Markdown (docs/nodes.md).
std::string node_reference_markdown(const NodeRegistry& registry);
// The output formats' options and the compress option schema (`atlas compress`
// flags = `dds` output options) as Markdown (docs/options.md; a test compares).
std::string options_reference_markdown();

} // namespace atlas
