// The superstorm options have one schema: the library's validate() and the two nodes'
// declarations (what a graph file may set, checked when the graph loads) must accept
// exactly the same values, and the nodes' defaults, ranges and units are the schema's.
#include "atlas/graph/node.h"
#include "atlas/ndf/superstorm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace atlas {
namespace {

NodeDeclaration declaration_of(const std::string& type) {
    const NodeRegistry registry = builtin_nodes();
    const NodeType* t = registry.find(type);
    if (!t) throw std::runtime_error("no node type " + type);
    NodeDeclaration d;
    t->declare(d);
    return d;
}

bool library_accepts(const NumberOption<ndf::SuperstormStencil>& o, double v) {
    ndf::SuperstormStencil s;
    s.*o.member = v;
    if (std::string(o.name) == "min_height") s.max_height = std::max(s.max_height, std::isfinite(v) ? v : 0.0);
    if (std::string(o.name) == "max_height") s.min_height = std::min(s.min_height, std::isfinite(v) ? v : 0.0);
    try {
        ndf::validate(s);
        return true;
    } catch (const Error&) {
        return false;
    }
}

// Values at and just past each bound, far outside, and not finite.
std::vector<double> probes(const NumberOption<ndf::SuperstormStencil>& o) {
    std::vector<double> v{0.0, -1.0, 0.5, 1.0, 1.5, 1e9, -1e9, std::nan(""), std::numeric_limits<double>::infinity()};
    for (double b : {o.min, o.max})
        if (std::isfinite(b)) {
            v.push_back(b);
            v.push_back(std::nextafter(b, -INFINITY));
            v.push_back(std::nextafter(b, INFINITY));
        }
    return v;
}

TEST(SuperstormSchema, NodesAndLibraryAcceptTheSameValues) {
    for (const std::string type : {"ndf/superstorm", "ndf/superstorm_anvil"}) {
        const NodeDeclaration d = declaration_of(type);
        int shared = 0;
        for (const auto& o : ndf::superstorm_options()) {
            const ParamDecl* p = d.find_param(o.name);
            if (!p) continue;
            ++shared;
            EXPECT_EQ(std::get<double>(p->default_value), o.default_value()) << type << " " << o.name;
            EXPECT_EQ(p->unit, o.unit) << type << " " << o.name;
            EXPECT_EQ(p->doc, o.doc) << type << " " << o.name;
            for (double v : probes(o)) {
                const bool node = p->check(ParamValue(v)).empty();
                // The graph refuses non-finite numbers when it parses them; the schema too.
                EXPECT_EQ(node && std::isfinite(v), library_accepts(o, v)) << type << " '" << o.name << "' = " << v;
            }
        }
        EXPECT_GE(shared, 4) << type << " declares the schema's options";
    }
}

TEST(SuperstormSchema, LibraryDefaultsAreValidAndMessagesNameTheOption) {
    EXPECT_NO_THROW(ndf::validate(ndf::SuperstormStencil{}));
    ndf::SuperstormStencil s;
    s.core = 1.0;
    try {
        ndf::validate(s);
        FAIL() << "core = 1 accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'core' must be in [0, 0.999]"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace atlas
