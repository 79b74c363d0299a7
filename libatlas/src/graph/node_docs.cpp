#include "atlas/graph/node_docs.h"

#include <algorithm>

#include "atlas/compress/compress_options.h"
#include "atlas/io/writers.h"

#include <sstream>

namespace atlas {

std::string tiling_refusal(const NodeDeclaration& decl) {
    const TileRule& r = decl.tiling();
    if (!r.why_not.empty()) return r.why_not;
    const auto& outs = decl.outputs();
    if (!outs.empty() && std::all_of(outs.begin(), outs.end(), [](const PortDecl& o) { return o.type == PortType::Points || o.type == PortType::Mesh; }))
        return "it makes no field (points or a mesh); a node that reads it whole tiles (volume/metaballs' points, "
               "volume/composite's cloud, volume/cutout's cutter: docs/scale.md)";
    return "its type declares no tiling rule (docs/scale.md lists the nodes that tile)";
}

namespace {
std::string first_sentence(const std::string& doc) {
    auto dot = doc.find(". ");
    return dot == std::string::npos ? doc : doc.substr(0, dot + 1);
}

std::string range_text(const ParamDecl& p) {
    if (p.type == ParamType::Enum) {
        std::string s;
        for (const auto& c : p.choices) s += (s.empty() ? "" : " | ") + c;
        return s;
    }
    auto num = [](double d) { return format_param_value(ParamValue(d)); };
    if (p.min && p.max) return "[" + num(*p.min) + ", " + num(*p.max) + "]";
    if (p.min) return ">= " + num(*p.min);
    if (p.max) return "<= " + num(*p.max);
    return "";
}

// How the node cooks in tiles (docs/scale.md).
std::string tiling_text(const NodeType& t) {
    const TileRule& r = t.decl.tiling();
    const bool source = t.decl.inputs().empty();
    std::string whole;
    for (const std::string& port : r.whole_inputs) whole += (whole.empty() ? "; '" : ", '") + port + "'";
    if (!whole.empty()) whole += " passed whole (any grid; what feeds it is cooked untiled)";
    switch (r.kind) {
    case TileRule::Kind::Pointwise:
        if (!source) return "pointwise" + whole;
        return r.window_grid ? "generator, makes each tile's window" : "generator, cooked whole and cropped";
    case TileRule::Kind::Halo: return "halo from its parameters" + whole;
    case TileRule::Kind::Whole: return "cooked whole once per process and cropped" + (r.why_not.empty() ? std::string() : ": " + r.why_not);
    case TileRule::Kind::None: break;
    }
    return "not tileable: " + tiling_refusal(t.decl);
}

std::string port_line(const PortDecl& p) {
    return std::string(port_type_name(p.type)) + (p.optional ? ", optional" : "");
}
} // namespace

std::string node_list_text(const NodeRegistry& registry) {
    std::ostringstream out;
    size_t w = 0;
    for (const NodeType* t : registry.all()) w = std::max(w, t->name.size());
    for (const NodeType* t : registry.all())
        out << t->name << std::string(w + 2 - t->name.size(), ' ') << first_sentence(t->decl.doc()) << "\n";
    return out.str();
}

std::string node_reference_text(const NodeType& t) {
    std::ostringstream out;
    out << t.name << " (version " << t.version << ")\n  " << t.decl.doc() << "\n  tiling: " << tiling_text(t) << "\n";
    if (!t.decl.inputs().empty()) {
        out << "\ninputs:\n";
        for (const auto& p : t.decl.inputs()) out << "  " << p.name << " (" << port_line(p) << "): " << p.doc << "\n";
    }
    out << "\noutputs:\n";
    for (const auto& p : t.decl.outputs()) out << "  " << p.name << " (" << port_line(p) << "): " << p.doc << "\n";
    if (!t.decl.params().empty()) {
        out << "\nparameters:\n";
        for (const auto& p : t.decl.params()) {
            out << "  " << p.name << " (" << param_type_name(p.type);
            if (!p.unit.empty()) out << ", " << p.unit;
            out << ") = " << format_param_value(p.default_value);
            if (auto r = range_text(p); !r.empty()) out << "  " << r;
            out << "\n      " << p.doc << "\n";
        }
    }
    return out.str();
}

namespace {
// What a proxy cook (CookOptions::proxy) does to the node: the parameters that follow it.
std::string proxy_text(const NodeType& t) {
    std::string scaled;
    for (const auto& p : t.decl.params()) {
        const char* how = p.proxy == ProxyScale::Cells        ? " / P (cells)"
                          : p.proxy == ProxyScale::CellLength ? " / P (a length in cells)"
                          : p.proxy == ProxyScale::CellSize   ? " x P (metres per cell)"
                                                               : nullptr;
        if (how) scaled += (scaled.empty() ? "" : ", ") + ("`" + p.name + "`" + how);
    }
    if (!scaled.empty()) return "at proxy P, " + scaled;
    bool grid_input = false;
    for (const auto& in : t.decl.inputs()) grid_input |= in.type == PortType::Field3D || in.type == PortType::Field2D || in.type == PortType::Field;
    return grid_input ? "follows its inputs' grids" : "not scaled (its size is not a world grid)";
}
} // namespace

std::string node_reference_markdown(const NodeRegistry& registry) {
    std::ostringstream out;
    out << "# Node reference\n\n"
        << "Generated from the node declarations by `atlas nodes --markdown`; do not edit by hand\n"
        << "(a test fails when this file is stale: regenerate it with\n"
        << "`build/apps/atlas nodes --markdown > docs/nodes.md`).\n\n";
    for (const NodeType* t : registry.all()) out << "- [`" << t->name << "`](#" << [&] {
            std::string a;
            for (char c : t->name) if (c != '/') a += c;
            return a;
        }() << ")\n";
    for (const NodeType* t : registry.all()) {
        out << "\n## " << t->name << "\n\n" << t->decl.doc() << " (version " << t->version << ")\n\n"
            << "Tiling: " << tiling_text(*t) << ".\n\n" << "Proxy: " << proxy_text(*t) << ".\n\n";
        if (!t->decl.inputs().empty()) {
            out << "| input | type | description |\n|---|---|---|\n";
            for (const auto& p : t->decl.inputs()) out << "| `" << p.name << "` | " << port_line(p) << " | " << p.doc << " |\n";
            out << "\n";
        }
        out << "| output | type | description |\n|---|---|---|\n";
        for (const auto& p : t->decl.outputs()) out << "| `" << p.name << "` | " << port_line(p) << " | " << p.doc << " |\n";
        out << "\n";
        if (!t->decl.params().empty()) {
            out << "| parameter | type | default | range | unit | description |\n|---|---|---|---|---|---|\n";
            for (const auto& p : t->decl.params())
                out << "| `" << p.name << "` | " << param_type_name(p.type) << " | `" << format_param_value(p.default_value) << "` | "
                    << range_text(p) << " | " << p.unit << " | " << p.doc << " |\n";
        }
    }
    return out.str();
}

namespace {
std::string md_cell(std::string s) {
    for (size_t i = 0; (i = s.find('|', i)) != std::string::npos; i += 2) s.replace(i, 1, "\\|");
    return s;
}
} // namespace

std::string options_reference_markdown() {
    std::ostringstream out;
    out << "# Option reference\n\n"
        << "Generated from the option schemas and the output format table by `atlas options --markdown`; do not\n"
        << "edit by hand (a test fails when this file is stale: regenerate it with\n"
        << "`build/bin/atlas options --markdown > docs/options.md`). Node parameters are in docs/nodes.md.\n\n"
        << "## Compress options\n\n"
        << "One schema (`compress::compress_options()`, atlas/compress/compress_options.h) for the `atlas compress`\n"
        << "flags and the `dds` output's options: both accept exactly the same values.\n\n"
        << "| dds option | `atlas compress` flag | accepts | description |\n|---|---|---|---|\n";
    for (const auto& o : compress::compress_options())
        out << "| `" << o.name << "` | " << md_cell(o.cli_flag ? "`" + std::string(o.cli_flag) + (*o.metavar ? " " + std::string(o.metavar) : "") + "`" : "")
            << " | " << md_cell(o.kind == OptionKind::Flag ? "true or false (the flag alone: true)" : o.expected()) << " | " << md_cell(o.doc)
            << " |\n";
    out << "\n## Output formats\n\nA graph output's `format` (or its file extension) and its `options` map; option values are\n"
        << "checked when the graph loads (`atlas validate` names the line).\n";
    for (const io::OutputFormat& f : io::output_formats()) {
        std::string ext, types;
        for (const auto& e : f.extensions) ext += (ext.empty() ? "" : ", ") + ("`" + e + "`");
        for (PortType t : f.accepts) types += (types.empty() ? "" : ", ") + std::string(port_type_name(t));
        out << "\n### " << f.name << "\n\n" << f.doc << ".\n\nExtensions: " << (ext.empty() ? "none (give `format`)" : ext)
            << ". Writes: " << types << ".\n\n"; // not the writer version: an encoder change is no docs change
        if (f.options.empty()) continue;
        out << "| option | description |\n|---|---|\n";
        for (const auto& [name, doc] : f.options) out << "| `" << name << "` | " << md_cell(doc) << " |\n";
    }
    return out.str();
}

} // namespace atlas
