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
#include "atlas/sim/sounding_options.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace atlas::sim_nodes {

// The record's channels are the Sounding schema's options, in its order
// (atlas/sim/sounding_options.h): one name and member list for node and record.
inline Field2D sounding_record(const sim::Sounding& s) {
    std::vector<std::string> names;
    for (const auto& o : sim::sounding_options()) names.emplace_back(o.name);
    Field2D f({{1, 1}}, int(names.size()), Box2d{{{0, 0}}, {{1, 1}}}, names);
    int c = 0;
    for (const auto& o : sim::sounding_options()) f.channel(c++)[0] = float(s.*o.member);
    return f;
}

// Reads a record made by sounding_record; fails naming the node and port when
// the field is not one (a field from another node wired by mistake).
inline sim::Sounding sounding_from_record(const CookContext& ctx, const Field2D& f, const std::string& port) {
    sim::Sounding s;
    if (f.width() != 1 || f.height() != 1)
        ctx.fail("input '" + port + "' must be a sim/sounding record (1 x 1), got " + std::to_string(f.width()) + " x " +
                 std::to_string(f.height()));
    for (const auto& o : sim::sounding_options()) {
        const int ch = f.find_channel(o.name);
        if (ch < 0) ctx.fail("input '" + port + "' is not a sim/sounding record (no channel '" + o.name + "')");
        s.*o.member = double(f.channel(ch)[0]);
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
