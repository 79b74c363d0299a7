// One schema per option set (issue 13): every front end accepts exactly the values
// another accepts, and docs/options.md is what the schemas generate.
//  - compress: `atlas compress` flags (the program, run as a script runs it) and a
//    graph's dds output options (checked as a graph load checks them);
//  - sounding: the sim/sounding node's parameters and Sounding::validate();
//  - solver: the sim/cloud_growth node's parameters and the SimOptions checks;
//  - grid parameters: one declaration for every node that has them;
//  - preview: `atlas preview` flags (the program) and the render/preview node's
//    parameters (checked as a graph load checks them), values and defaults.
#include "atlas/compress/compress_options.h"
#include "atlas/core/files.h"
#include "atlas/graph/node.h"
#include "atlas/graph/node_docs.h"
#include "atlas/graph/option_params.h"
#include "atlas/io/writers.h"
#include "atlas/render/preview_options.h"
#include "atlas/sim/sim_options.h"
#include "atlas/sim/sounding_options.h"

#include "../support/cli_run.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace atlas {
namespace {

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

// Boundary values of one option: at and just outside its bounds, a non-integer for
// integers, NaN / Inf, malformed text, its first and last word and a wrong one.
std::vector<std::string> probes(const TextOptionSpec& o) {
    std::vector<std::string> v{"", "nan"};
    switch (o.kind) {
    case OptionKind::Number:
        v.insert(v.end(), {"inf", "abc", num(o.min), num(std::nextafter(o.min, -INFINITY)), num(o.max), num(std::nextafter(o.max, INFINITY))});
        break;
    case OptionKind::Integer: v.insert(v.end(), {num(o.min), num(o.min - 1), num(o.max), num(o.max + 1), "2.7", "inf"}); break;
    case OptionKind::Choice: break;
    case OptionKind::List:
        if (o.words.empty()) v.insert(v.end(), {"value", "value,", ",value"});
        else v.insert(v.end(), {o.words[0] + "," + o.words[1], o.words[0] + ",," + o.words[1], o.words[0] + ","});
        break;
    case OptionKind::Range:
        v.insert(v.end(), {"0,1", "1,0", "0,inf", "0,1,2", num(o.min) + ",0", "0," + num(o.max), "0," + num(std::nextafter(o.max, INFINITY) * 1.01)});
        break;
    case OptionKind::Flag: break;
    case OptionKind::Text: v.insert(v.end(), {"x", ";"}); break;
    }
    if (!o.words.empty()) v.insert(v.end(), {o.words.front(), o.words.back(), o.words.back() + "x"});
    return v;
}

bool dds_output_accepts(const std::string& option, const std::string& text) {
    try {
        io::check_output_options("dds", "x.dds", {{option, text}, {"encoding", "r8"}}, PortType::Field2D);
        return true;
    } catch (const Error&) {
        return false;
    }
}

using test::CliRun;

CliRun run(const std::string& args) {
    const fs::path dir = test::process_dir("atlas_options_test");
    return test::run_shell(test::atlas_program() + " " + args + " 2>" + (dir / "err").string(), dir / "err");
}

TEST(OptionsSchema, DocsOptionsMdIsUpToDate) {
    const std::string expected = options_reference_markdown() + render::preview_options_markdown();
    std::string actual;
    ASSERT_NO_THROW(actual = read_file_bytes(std::string(ATLAS_SOURCE_DIR) + "/docs/options.md"));
    EXPECT_TRUE(actual == expected) << "docs/options.md is stale: regenerate it with 'build/bin/atlas options --markdown > docs/options.md'";
    CliRun r = run("options --markdown");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, expected);
}

// The dds output's options and `atlas compress`'s flags are the schema's, documented
// with every word the option takes (bc6h and bc6h-sf16 were missing from 'encoding').
TEST(OptionsSchema, EveryCompressOptionIsAFlagAndADdsOption) {
    const io::OutputFormat* dds = nullptr;
    for (const auto& f : io::output_formats())
        if (f.name == "dds") dds = &f;
    ASSERT_TRUE(dds);
    CliRun help = run("compress --help");
    for (const auto& o : compress::compress_options()) {
        bool documented = false;
        for (const auto& [name, doc] : dds->options)
            if (name == o.name) {
                documented = true;
                for (const std::string& w : o.words) EXPECT_NE(doc.find("'" + w + "'"), std::string::npos) << o.name << " lacks " << w;
            }
        EXPECT_TRUE(documented) << o.name;
        ASSERT_TRUE(o.cli_flag) << o.name;
        EXPECT_NE(help.out.find(std::string("  ") + o.cli_flag + " "), std::string::npos) << o.cli_flag << "\n" << help.out;
        for (const std::string& w : o.words) EXPECT_NE(help.out.find(w), std::string::npos) << o.cli_flag << " help lacks " << w;
    }
    EXPECT_EQ(dds->options.size(), compress::compress_options().size());
}

TEST(OptionsSchema, CompressFlagsAndDdsOptionsAcceptTheSameValues) {
    const fs::path dir = test::process_dir("atlas_options_cli");
    // A small 2D input with one channel named 'value' (the List-of-names probes use it).
    auto field = std::make_shared<Field2D>(Vec2i{{8, 8}}, 1, Box2d{{{0, 0}}, {{1, 1}}}, std::vector<std::string>{"value"});
    for (size_t i = 0; i < field->channel(0).size(); ++i) field->channel(0)[i] = float(i % 7) / 7.0f;
    const fs::path in = dir / "in.exr";
    io::write_value(Field2DPtr(field), in, "exr", {});
    const fs::path out = dir / "out.dds";
    int runs = 0;
    for (const auto& o : compress::compress_options()) {
        const std::string base = "compress " + in.string() + " --quiet --no-verify -o " + out.string();
        // --format is the option itself for 'encoding'; the others use r8 (every option applies to it).
        const std::string format = std::string(o.name) == "encoding" ? "" : " --format r8";
        if (o.kind == OptionKind::Flag) {
            // A flag takes no value and means true, as the option's 'true'.
            EXPECT_TRUE(dds_output_accepts(o.name, "true"));
            CliRun c = run(base + format + " " + o.cli_flag);
            EXPECT_EQ(c.status, 0) << o.cli_flag << ": " << c.err;
            EXPECT_EQ(run(base + format + " '" + o.cli_flag + "=true'").status, 2) << o.cli_flag << " takes no value";
            continue;
        }
        for (const std::string& text : probes(o)) {
            const bool graph = dds_output_accepts(o.name, text);
            fs::remove(out);
            CliRun c = run(base + format + " '" + o.cli_flag + "=" + text + "'");
            ++runs;
            const bool cli = c.status != 2;
            EXPECT_EQ(cli, graph) << o.cli_flag << " '" << text << "': CLI status " << c.status << " " << c.err << " / graph "
                                  << (graph ? "accepts" : "refuses");
            // (An accepted value may still fail on this input, e.g. max_error 0 for r8: status 1.)
            if (!cli) {
                EXPECT_NE(c.err.find(std::string(o.cli_flag) + " expects " + o.expected()), std::string::npos) << c.err;
            }
        }
    }
    EXPECT_GT(runs, 40);
    fs::remove_all(dir);
}

NodeDeclaration declaration_of(const std::string& type) {
    const NodeRegistry registry = builtin_nodes();
    const NodeType* t = registry.find(type);
    if (!t) throw std::runtime_error("no node type " + type);
    NodeDeclaration d;
    t->declare(d);
    return d;
}

// The node's parameters and the library's validate() take the same sounding values;
// the node's defaults are the named preset, valid by the library's rule.
TEST(OptionsSchema, SoundingNodeAndLibraryAcceptTheSameValues) {
    const NodeDeclaration d = declaration_of("sim/sounding");
    const sim::Sounding preset = sim::capped_boundary_layer_sounding();
    EXPECT_NO_THROW(preset.validate());
    EXPECT_NO_THROW(sim::Sounding{}.validate());
    for (const auto& o : sim::sounding_options()) {
        const ParamDecl* p = d.find_param(o.name);
        ASSERT_TRUE(p) << o.name;
        EXPECT_EQ(std::get<double>(p->default_value), preset.*o.member) << o.name;
        EXPECT_EQ(p->unit, o.unit) << o.name;
        std::vector<double> values{0.0, -1.0, 0.5, 1.0, 1e9, -1e9, std::nan(""), std::numeric_limits<double>::infinity()};
        for (double b : {o.min, o.max})
            for (double x : {b, std::nextafter(b, -INFINITY), std::nextafter(b, INFINITY)}) values.push_back(x);
        for (double v : values) {
            sim::Sounding s = preset;
            s.*o.member = v;
            bool library = true;
            try {
                s.validate();
            } catch (const Error&) {
                library = false;
            }
            // The graph refuses non-finite numbers when it parses them.
            const bool node = p->check(ParamValue(v)).empty() && std::isfinite(v);
            EXPECT_EQ(node, library) << o.name << " = " << v;
        }
    }
}

// sim/cloud_growth declares the solver's options from sim::sim_options() with the
// library's defaults (SimOptions{}), and the library check of each number refuses
// exactly what the node's parameter refuses: SimOptions::validate its own members,
// KesslerOptions::validate (with rain) the rain_* ones, the pressure solver the
// pressure_* ones.
TEST(OptionsSchema, SimNodeAndLibraryAcceptTheSameValues) {
    const NodeDeclaration d = declaration_of("sim/cloud_growth");
    const sim::SimOptions defaults;
    EXPECT_NO_THROW(defaults.validate(8));
    sim::GridSpec grid;
    grid.nx = grid.ny = grid.nz = 4;
    grid.dx = 100;
    sim::PressureSolver solver(grid);
    for (const TextOption<sim::SimOptions>& o : sim::sim_options()) {
        const ParamDecl* p = d.find_param(o.name);
        ASSERT_TRUE(p) << o.name;
        EXPECT_EQ(p->type, text_option_param_type(o)) << o.name;
        EXPECT_EQ(p->unit, o.unit) << o.name;
        EXPECT_EQ(p->doc, o.doc) << o.name;
        OptionValue node_default;
        ASSERT_TRUE(parse_text_option(o, text_option_text(o, p->default_value), node_default)) << o.name;
        EXPECT_EQ(option_value_text(o, node_default), option_value_text(o, o.value_of(defaults))) << o.name;
        if (o.kind != OptionKind::Number && o.kind != OptionKind::Integer) continue;
        const bool integer = o.kind == OptionKind::Integer;
        std::vector<double> values{0.0, -1.0, 0.5, 1.0, 64, 1e9, -1e9};
        for (double b : {o.min, o.max})
            for (double x : {b, std::nextafter(b, -INFINITY), std::nextafter(b, INFINITY), b - 1, b + 1}) values.push_back(x);
        if (!integer) values.insert(values.end(), {std::nan(""), std::numeric_limits<double>::infinity()});
        for (double v : values) {
            if (integer && v != std::floor(v)) continue;
            sim::SimOptions s = defaults;
            OptionValue value;
            value.number = v;
            o.apply(s, value);
            bool library = true;
            try {
                const std::string_view name = o.name;
                if (name.starts_with("pressure_")) {
                    sim::MacVelocity vel(grid);
                    solver.project(vel, s.projection);
                } else {
                    s.rain = name.starts_with("rain_");
                    s.validate(8);
                }
            } catch (const Error&) {
                library = false;
            }
            // The graph refuses non-finite numbers when it parses them.
            const ParamValue param = integer ? ParamValue(int64_t(v)) : ParamValue(v);
            const bool node = p->check(param).empty() && std::isfinite(v);
            EXPECT_EQ(node, library) << o.name << " = " << v;
        }
    }
}

// Every node with grid parameters declares them alike (type, range, unit, doc); the
// defaults are the family's own (nodes/common/grid.h).
TEST(OptionsSchema, GridParametersAreDeclaredAlike) {
    const NodeRegistry registry = builtin_nodes();
    std::map<std::string, const ParamDecl*> first; // "resolution/2" etc. -> first declaration seen
    int nodes = 0;
    for (const NodeType* t : registry.all()) {
        NodeDeclaration d;
        t->declare(d);
        const ParamDecl* lo = d.find_param("bounds_min");
        const ParamDecl* hi = d.find_param("bounds_max");
        if (!lo || !hi || lo->doc != "world-space minimum corner") continue; // other meanings (resample, transform) are their own
        ++nodes;
        EXPECT_EQ(lo->type, hi->type) << t->name;
        EXPECT_EQ(lo->unit, "m") << t->name;
        EXPECT_EQ(hi->doc, "world-space maximum corner") << t->name;
        if (const ParamDecl* r = d.find_param("resolution")) {
            EXPECT_EQ(r->min, 1.0) << t->name;
            EXPECT_EQ(r->max, 65536.0) << t->name;
            EXPECT_EQ(r->unit, r->type == ParamType::Int2 ? "texels" : "voxels") << t->name;
        }
    }
    EXPECT_GE(nodes, 20);
}

// ---------------------------------------------------------------------------
// Preview: `atlas preview`'s flags and the render/preview node's parameters.

// How the CLI spells an option without a flag of its own: the flag and a template
// whose "{}" is the option's text (the other parts valid).
const std::map<std::string, std::string> kPreviewSpelled = {
    {"view", "--view={}"},
    {"azimuth", "--view=orbit:{},20"},
    {"elevation", "--view=orbit:30,{}"},
    {"position", "--camera={},1,2,3"},
    {"look_at", "--camera=1,2,3,{}"},
    {"sun_azimuth", "--sun={},20"},
    {"sun_elevation", "--sun=30,{}"},
    {"sky_colour", "--sky={},0.5,0.5,0.5"},
    {"sky_horizon", "--sky=0.5,0.5,0.5,{}"},
    {"flash_count", "--lightning={}"},
    {"flash_intensity", "--lightning=2,{}"},
    {"flash_radius", "--lightning=2,1,{}"},
};
// Options the CLI sets only to one value (camera manual by --camera, mode reference by
// --reference, lightning by --lightning, flash_schedule off by --no-flash-schedule):
// probed on the node side only.
const std::vector<std::string> kPreviewNodeOnly = {"camera", "mode", "lightning", "flash_schedule"};
// Options that need another one to mean anything: the flags the CLI probe adds (the
// node checks each parameter alone when the graph loads).
const std::map<std::string, std::string> kPreviewContext = {{"ms_octaves", "--artistic=off"}, {"ms_diffusion", "--artistic=off"}};

struct Probe {
    std::string text; // as the CLI takes it
    ParamValue node;  // as a graph file gives it
};

// Probes of a numeric option: one component at and past the bounds, NaN, Inf, a
// non-integer, malformed text; the other components at a valid value.
std::vector<Probe> preview_probes(const TextOptionSpec& o) {
    std::vector<Probe> v;
    const ParamType type = text_option_param_type(o);
    const bool numeric = o.kind == OptionKind::Number || o.kind == OptionKind::Integer;
    if (numeric && type != ParamType::String) {
        const bool integer = o.kind == OptionKind::Integer;
        const double ok = std::clamp(1.0, o.min, o.max);
        std::vector<double> xs{ok, NAN, INFINITY, 2.7};
        for (double b : {o.min, o.max})
            if (std::isfinite(b)) xs.insert(xs.end(), {b, integer ? b + (b == o.min ? -1 : 1) : std::nextafter(b, b == o.min ? -INFINITY : INFINITY)});
        for (double x : xs) {
            std::vector<double> comps(size_t(o.count), ok);
            comps[0] = x;
            std::string text;
            for (double c : comps) text += (text.empty() ? "" : std::string(1, o.separator)) + num(c);
            ParamValue node;
            if (o.count > 1) node = comps;
            else if (integer && std::isfinite(x) && x == std::floor(x)) node = int64_t(x);
            else node = x; // a graph gives a non-integer as a float, which an int parameter refuses
            v.push_back({text, node});
        }
        v.push_back({"abc", std::string("abc")});
        return v;
    }
    for (const std::string& t : probes(o)) v.push_back({t, t});
    if (o.kind == OptionKind::Flag) v.insert(v.end(), {{"true", true}, {"false", false}});
    if (numeric) // a string parameter with words and numbers
        for (const std::string& t : {std::string("1,1,1"), std::string("-1,1,1"), std::string("1,1"), std::string("1e7,1,1"), std::string("nan,1,1")})
            v.push_back({t, t});
    if (o.kind == OptionKind::Text) v.push_back({"1,2,3,1,1,1,100; 4 5 6 1 1 1 2e3 50", std::string("1,2,3,1,1,1,100; 4 5 6 1 1 1 2e3 50")});
    return v;
}

std::string replace_braces(std::string t, const std::string& text) { return t.replace(t.find("{}"), 2, text); }

// `atlas preview` refuses a flag's value with status 2 before it reads its input;
// an accepted value gets as far as the missing input file (status 1).
bool preview_cli_accepts(const std::string& flag_and_value, std::string* err = nullptr, const std::string& context = "") {
    CliRun r = run("preview /nonexistent/atlas_options_test.vdb --noise none --quiet " + context + " '" + flag_and_value + "' -o x.png");
    if (err) *err = r.err;
    EXPECT_TRUE(r.status == 1 || r.status == 2) << flag_and_value << ": status " << r.status << " " << r.err;
    return r.status != 2;
}

TEST(OptionsSchema, PreviewFlagsAndNodeParametersAcceptTheSameValues) {
    const NodeDeclaration d = declaration_of("render/preview");
    const auto schema = render::preview_options();
    int runs = 0;
    for (const auto& o : schema) {
        const ParamDecl* p = d.find_param(o.name);
        ASSERT_TRUE(p) << o.name;
        EXPECT_EQ(p->type, text_option_param_type(o)) << o.name;
        EXPECT_EQ(p->unit, o.unit) << o.name;
        EXPECT_EQ(p->doc, o.doc) << o.name;
        const bool node_only = std::find(kPreviewNodeOnly.begin(), kPreviewNodeOnly.end(), o.name) != kPreviewNodeOnly.end();
        const auto spelled = kPreviewSpelled.find(o.name);
        // Every option is a flag, spelled by one, or listed as node-only: a new option needs a decision here.
        EXPECT_EQ(int(o.cli_flag != nullptr) + int(spelled != kPreviewSpelled.end()) + int(node_only), 1) << o.name;
        int node_yes = 0, node_no = 0;
        for (const Probe& pr : preview_probes(o)) {
            const bool node = p->check(pr.node).empty();
            (node ? node_yes : node_no)++;
            // The node's value, read back through the schema, is what the CLI's text gives.
            if (node && !node_only) {
                render::PreviewOptions from_node, from_cli;
                EXPECT_TRUE(set_text_option(o, text_option_text(o, pr.node), from_node)) << o.name << " " << pr.text;
                EXPECT_TRUE(set_text_option(o, pr.text, from_cli)) << o.name << " " << pr.text;
                EXPECT_TRUE(from_node == from_cli) << o.name << " " << pr.text;
            }
            if (node_only) continue;
            // Spelled options: the spelling's other parts are numbers, so words go through own flags only.
            if (spelled != kPreviewSpelled.end() && o.kind == OptionKind::Number && !o.words.empty() && pr.text.find_first_of("0123456789") == std::string::npos)
                continue;
            const std::string arg = o.cli_flag ? std::string(o.cli_flag) + "=" + pr.text : replace_braces(spelled->second, pr.text);
            std::string err;
            const auto context = kPreviewContext.find(o.name);
            const bool cli = preview_cli_accepts(arg, &err, context == kPreviewContext.end() ? "" : context->second);
            ++runs;
            EXPECT_EQ(cli, node) << arg << ": CLI " << (cli ? "accepts" : "refuses") << " (" << err << "), node parameter '" << o.name << "' "
                                 << (node ? "accepts" : "refuses: " + p->check(pr.node));
            if (!cli && o.cli_flag) {
                EXPECT_NE(err.find(std::string(o.cli_flag) + " expects " + o.expected()), std::string::npos) << err;
            }
        }
        // The probes are not vacuous: each option takes some and refuses some.
        EXPECT_GT(node_yes, 0) << o.name;
        EXPECT_GT(node_no, 0) << o.name;
    }
    EXPECT_GT(runs, 150);
}

TEST(OptionsSchema, PreviewDefaultsAreOneAndTheNodesPresetIsNamed) {
    const NodeDeclaration d = declaration_of("render/preview");
    // The struct's initializers are the schema's default texts.
    render::PreviewOptions from_texts;
    for (const auto& o : render::preview_options()) {
        if (o.default_text.empty()) continue;
        EXPECT_TRUE(set_text_option(o, o.default_text, from_texts)) << o.name << " default '" << o.default_text << "'";
    }
    EXPECT_TRUE(from_texts == render::PreviewOptions{});
    // The node's defaults are the CLI's, except the named preset (size 480x270).
    int presets = 0;
    for (const auto& o : render::preview_options()) {
        const ParamDecl* p = d.find_param(o.name);
        ASSERT_TRUE(p) << o.name;
        std::string cli_default = o.default_text;
        for (const auto& [name, text] : render::preview_node_defaults())
            if (name == std::string(o.name)) cli_default = text, ++presets;
        render::PreviewOptions node, cli;
        ASSERT_TRUE(set_text_option(o, text_option_text(o, p->default_value), node)) << o.name;
        ASSERT_TRUE(set_text_option(o, cli_default, cli)) << o.name;
        EXPECT_TRUE(node == cli) << o.name << ": node default " << format_param_value(p->default_value) << ", CLI '" << cli_default << "'";
    }
    EXPECT_EQ(presets, 1);
    EXPECT_EQ(std::get<std::vector<double>>(d.find_param("size")->default_value), (std::vector<double>{480, 270}));
    // A negative control: a different default is seen as different.
    render::PreviewOptions a, b;
    ASSERT_TRUE(set_text_option(*find_option(render::preview_options(), "fov"), "40", b));
    EXPECT_FALSE(a == b);
    // The spellings' help names every option they set; --sun's default is the library's preview sun.
    CliRun help = run("preview --help");
    for (const auto& sp : render::preview_cli_spellings()) EXPECT_NE(help.out.find(std::string("  ") + sp.cli_flag), std::string::npos) << sp.cli_flag;
    for (const auto& o : render::preview_options())
        if (o.cli_flag) {
            EXPECT_NE(help.out.find(std::string("  ") + o.cli_flag + " "), std::string::npos) << o.cli_flag;
        }
    EXPECT_NE(help.out.find("default 230,25"), std::string::npos) << help.out;
    // The physical model's options need artistic off, in both front ends.
    EXPECT_EQ(run("preview /nonexistent/x.vdb --noise none --ms-octaves 4 -o x.png").status, 2);
    EXPECT_EQ(run("preview /nonexistent/x.vdb --noise none --artistic off --ms-octaves 4 -o x.png").status, 1);
    render::PreviewOptions physical;
    ASSERT_TRUE(set_text_option(*find_option(render::preview_options(), "ms_diffusion"), "off,8", physical));
    EXPECT_THROW(render::check_preview_options(physical), Error);
    ASSERT_TRUE(set_text_option(*find_option(render::preview_options(), "artistic"), "off", physical));
    EXPECT_NO_THROW(render::check_preview_options(physical));
}

} // namespace
} // namespace atlas
