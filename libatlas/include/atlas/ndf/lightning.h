// atlas/ndf/lightning.h - a superstorm's lightning as a schedule an engine plays (000,
// "Lightning Effects"): strike sequences of several intra-cloud flashes of rising
// intensity, then one or two ground discharges, placed where the NDF set's storm is.
//
// Time is cut into one-second slots; slot k starts a sequence with probability
// rate / 60 (a hash of seed and k), at a hashed offset within the slot, in a column
// drawn from the set's storm (superstorm_coverage, else precipitation, else coverage)
// with probability proportional to its value. The flashes of a sequence follow
// `spacing` apart: intra-cloud flashes 30-60 % up the column's cloud, rising to half the
// intensity, then the ground discharges from the column's base at full intensity. A
// schedule lists the flashes that start in [time, time + window); windows that tile
// time list every flash once (the slots do not depend on the window), so frames of a
// sequence agree. The rate is the one given for the window (key it over the storm's
// life; within a window it is constant). Pure, deterministic, thread-safe.
#pragma once

#include "atlas/core/field.h"

#include <cstdint>
#include <vector>

namespace atlas::ndf {

struct LightningOptions {
    double time = 0;        // seconds: the window's start
    double window = 1;      // seconds (> 0, <= 86400): the window listed, e.g. a frame's length
    double rate = 2;        // [0, 60] strike sequences per minute
    int intra_flashes = 3;  // [0, 16] intra-cloud flashes before the ground discharges
    int ground_max = 2;     // [0, 4]: 1..ground_max ground discharges per sequence (0: none)
    double spacing = 0.4;   // seconds (> 0, <= 10) between a sequence's flashes
    double duration = 0.2;  // seconds (> 0, <= 10): a flash's lifetime
    double intensity = 1e5; // (>= 0) a ground discharge's intensity (the preview's flash units)
    uint32_t seed = 1;
};

struct Flash {
    double time = 0, duration = 0; // seconds
    Vec3d position{};              // metres: intra-cloud, in the cloud; ground, at the column's base
    double intensity = 0;
    bool ground = false;
    int64_t sequence = 0; // the slot that started it
};

// Throws atlas::Error naming the option for values outside the ranges above, and
// for a set without min_height/max_height channels.
std::vector<Flash> lightning_schedule(const Field2D& set, const LightningOptions& options);

// The schedule as a table (x = flash, one row; an empty schedule is one row with
// intensity 0 and time -1) over the set's bounds, channels time, duration, x, y, z,
// intensity, ground (0/1), sequence: write it as JSON (a `.json` output).
Field2D lightning_table(const std::vector<Flash>& flashes, const Box2d& bounds);

} // namespace atlas::ndf
