// Shared by the sim nodes (not a node): how a Sounding travels along a graph
// edge, and how solver errors are made to name the node.
//
// Graph values are fields, so sim/sounding sends its parameters as a 1 x 1
// Field2D "record" with one channel per Sounding member (names below, SI
// units). Floats hold every documented value closely enough (relative 6e-8).
#pragma once

#include "atlas/core/error.h"
#include "atlas/graph/node.h"
#include "atlas/sim/simulation.h"

#include <array>
#include <memory>
#include <utility>

namespace atlas::sim_nodes {

// Channel names of the sounding record, in order.
inline const std::array<const char*, 11>& sounding_channels() {
    static const std::array<const char*, 11> names = {"surface_pressure", "surface_theta",   "theta_lapse",       "inversion_height",
                                                      "inversion_jump",   "inversion_depth", "theta_lapse_above", "surface_rh",
                                                      "rh_lapse",         "rh_above",        "total_water"};
    return names;
}

inline std::array<double*, 11> sounding_members(sim::Sounding& s) {
    return {&s.surface_pressure, &s.surface_theta, &s.theta_lapse,       &s.inversion_height, &s.inversion_jump, &s.inversion_depth,
            &s.theta_lapse_above, &s.surface_rh,   &s.rh_lapse,          &s.rh_above,         &s.total_water};
}

inline Field2D sounding_record(sim::Sounding s) {
    const auto& names = sounding_channels();
    Field2D f({{1, 1}}, int(names.size()), Box2d{{{0, 0}}, {{1, 1}}}, std::vector<std::string>(names.begin(), names.end()));
    const auto members = sounding_members(s);
    for (size_t c = 0; c < members.size(); ++c) f.channel(int(c))[0] = float(*members[c]);
    return f;
}

// Reads a record made by sounding_record; fails naming the node and port when
// the field is not one (a field from another node wired by mistake).
inline sim::Sounding sounding_from_record(const CookContext& ctx, const Field2D& f, const std::string& port) {
    sim::Sounding s;
    const auto& names = sounding_channels();
    const auto members = sounding_members(s);
    if (f.width() != 1 || f.height() != 1)
        ctx.fail("input '" + port + "' must be a sim/sounding record (1 x 1), got " + std::to_string(f.width()) + " x " +
                 std::to_string(f.height()));
    for (size_t c = 0; c < names.size(); ++c) {
        const int ch = f.find_channel(names[c]);
        if (ch < 0) ctx.fail("input '" + port + "' is not a sim/sounding record (no channel '" + names[c] + "')");
        *members[c] = double(f.channel(ch)[0]);
    }
    try {
        s.validate();
    } catch (const CancelledError&) {
        throw;
    } catch (const Error& e) {
        ctx.fail(std::string("input '") + port + "': " + e.what());
    }
    return s;
}

} // namespace atlas::sim_nodes
