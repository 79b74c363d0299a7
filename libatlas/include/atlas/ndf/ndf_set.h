// atlas/ndf/ndf_set.h - the NDF set: named 2D channels over the world XY plane.
//
// An NDF set is a Field2D with exactly these channels, in this order:
//   coverage             [0,1]  probability of cloud
//   type                 [0,1]  0 stratus, 1/3 stratocumulus, 2/3 cumulus, 1 cumulonimbus
//   top_type             [0,1]  type driving the upper falloff (HFW vertical profile)
//   bottom_type          [0,1]  type driving the lower rise (1 = ragged storm base)
//   min_height           metres above the layer origin: cloud base
//   max_height           metres: cloud top (>= min_height)
//   precipitation        [0,1]  chance of rain
//   superstorm_coverage  [0,1]  weight of superstorm stencils
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <array>
#include <string>

namespace atlas::ndf {

enum NdfChannel : int { Coverage = 0, Type, TopType, BottomType, MinHeight, MaxHeight, Precipitation, SuperstormCoverage, ChannelCount };

// The channel names in order (see the table above).
const std::array<std::string, ChannelCount>& ndf_channel_names();

// A set filled with defaults: coverage 0, types 0, min_height `min_height`,
// max_height `max_height`, precipitation 0, superstorm 0. Throws when
// min_height > max_height or either is not finite.
Field2D make_ndf_set(Vec2i res, Box2d bounds, double min_height, double max_height, const MemoryBudget* budget);

// Throws atlas::Error unless `f` has the NDF set's channel names in order.
void check_ndf_set(const Field2D& f);

// Horizon Zero Dawn's rain rule: where rain is certain, clouds are storm
// clouds. w = smoothstep(rain_start, rain_full, precipitation);
// type' = lerp(type, storm_type, w), top_type likewise,
// coverage' = lerp(coverage, max(coverage, min_coverage), w).
// At precipitation >= rain_full: type = storm_type and coverage >= min_coverage.
struct PrecipitationRule {
    double rain_start = 0.7;   // below: no change
    double rain_full = 1.0;    // at and above: full effect (> rain_start)
    double min_coverage = 0.7; // HZD: "coverage at least 70%"
    double storm_type = 1.0;   // cumulonimbus
};
Field2D apply_precipitation_rule(const Field2D& set, const PrecipitationRule& rule, const MemoryBudget* budget);

// smoothstep(e0, e1, x) with the 3t^2 - 2t^3 polynomial, clamped; e0 == e1 is a step.
double smoothstep(double e0, double e1, double x);

} // namespace atlas::ndf
