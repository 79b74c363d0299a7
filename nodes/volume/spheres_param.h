// Shared by the volume nodes (not a node): the `spheres` parameter, "x y z radius; ...".
#pragma once

#include "atlas/graph/node.h"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace atlas::volume_nodes {

inline void declare_spheres(NodeDeclaration& d) {
    d.param_string("spheres", "").describe("spheres as 'x y z radius' in metres, separated by ';' (may be empty)");
}

// Appends the `spheres` parameter's spheres to `pts` (radius into `radius`,
// weight 1 when the points carry weights). Fails the cook naming the item.
inline void append_spheres(const CookContext& ctx, Points& pts, std::vector<float>& radius) {
    const bool had_weight = pts.attributes.count("weight") > 0;
    std::stringstream all(ctx.get_string("spheres"));
    for (std::string item; std::getline(all, item, ';');) {
        std::stringstream one(item);
        std::vector<std::string> tok;
        for (std::string t; one >> t;) tok.push_back(t);
        if (tok.empty()) continue;
        double v[4];
        bool ok = tok.size() == 4;
        for (size_t i = 0; ok && i < 4; ++i) {
            char* end = nullptr;
            v[i] = std::strtod(tok[i].c_str(), &end);
            ok = end != tok[i].c_str() && *end == '\0' && std::isfinite(v[i]);
        }
        if (!ok) ctx.fail("spheres: expected 'x y z radius' (finite numbers) separated by ';', got '" + item + "'");
        pts.positions.push_back({{float(v[0]), float(v[1]), float(v[2])}});
        radius.push_back(float(v[3]));
        if (had_weight) pts.attributes["weight"].push_back(1.0f);
    }
}

} // namespace atlas::volume_nodes
