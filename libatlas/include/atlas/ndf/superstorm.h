// atlas/ndf/superstorm.h - HFW superstorm stencils: mesocyclone and vortex rings.
//
// A stencil overrides an NDF set radially. With r the distance to `center`,
// g(r) = 1 - smoothstep(core * radius, radius, r) (1 in the core, 0 at and
// beyond `radius`) and w = blend * g:
//   coverage'   = lerp(coverage, max(coverage, stencil coverage), w)
//   type', top_type' = lerp(x, storm_type, w)
//   bottom_type' = lerp(x, max(x, bottom_type), w)
//   superstorm_coverage' = max(x, w)
//   min/max_height' = lerp(x, storm min/max height, blend * g_h(r_d)) (g_h: g
//   with height_core in place of core when height_core >= 0) where the
//   distorted radius r_d = r * (1 + distortion * (2 n - 1) * (1 - r / radius))
//   for r < radius (n: tileable value noise), r_d = r beyond: unchanged at the
//   centre and beyond the radius, wobbly in between.
// Beyond the radius the map is unchanged; blend 0 leaves it bit-identical.
//
// Downwind stretch: with stretch > 1 the footprint is a plume, not a disc.
// Along `wind_direction` (degrees from +x toward +y) the downwind half's
// radius is stretch * radius (the upwind half keeps radius): r is measured
// as length(a / s, c) with a the downwind and c the crosswind offset, s =
// stretch where a > 0, else 1. stretch 1 is the disc, bit-identical.
//
// Sheet heights (an anvil, 000's "flattens at the top and spreads in the
// wind direction"): instead of blending the map's heights radially, every
// column inside the distorted footprint (w_d = blend * g(r_d) > 0) becomes
// the stencil's sheet: max_height' = max_height (a flat top), min_height' =
// max_height - (max_height - min_height) * w_d (the underside rises toward
// the rim), coverage' = coverage * w_d (the map's own cloud in those
// columns is replaced: one layer per column), types as above. Chain a
// radial stencil after it for the tower that feeds the sheet.
// Pure, thread-safe, deterministic.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include "atlas/core/option_schema.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace atlas::ndf {

struct SuperstormStencil {
    Vec2d center{{0, 0}};     // metres
    double radius = 8000;     // metres, > 0
    double core = 0.3;        // fraction of the radius at full strength, [0,1)
    double coverage = 1.0;    // [0,1]
    double blend = 1.0;       // [0,1]
    double storm_type = 1.0;  // cumulonimbus
    double bottom_type = 1.0; // ragged underside
    double min_height = 800;  // metres, storm base at the centre
    double max_height = 9000; // metres, storm top at the centre (>= min_height)
    double distortion = 0.3;  // [0,1): radial wobble of the height gradients
    double noise_scale = 4;   // noise lattice cells across the radius
    uint32_t seed = 0;
    // Anvil: how far the storm's top spreads out ([0,1]); written to the
    // separate anvil map (superstorm_anvil), not to the 8-channel set.
    double anvil = 1.0;
    // Anvil lift: metres the anvil may rise above the set's max_height where
    // the anvil map's bias is 1 (lift = anvil_lift * bias, so 0 where the
    // bias is 0); [0, 20000] m. The anvil map only.
    double anvil_lift = 1500;
    // Fraction of the radius inside which the heights are the storm's (the
    // height blend's core; a flat base that wide); < 0 = core.
    double height_core = -1;
    // Wobble of the footprint itself ([0, 1)): coverage and types use
    // r_c = r * (1 + edge_noise * (0.6 (2 n - 1) + 0.4 (2 n2 - 1)) * (1 - r / radius)),
    // n2 a second value-noise octave at twice the frequency. 0 = round.
    double edge_noise = 0;
    // Plume: downwind radius = stretch * radius (>= 1; 1 = disc).
    double stretch = 1.0;
    double wind_direction = 0; // degrees from +x toward +y
    // Billowed wall ([0, 1)): a three-octave value-noise wobble of the
    // heights' radius at 2, 4 and 8 times noise_scale, as a fraction of the
    // height band's width (radius - height core), so the wall between the
    // storm's columns and the map's is lumpy at every scale instead of a smooth
    // cylinder. It fades out over the outer quarter of the band. 0 = none.
    double wall_noise = 0;
    // Base relief (metres, >= 0): the storm's base rises by up to this much
    // following a two-octave noise at 2 and 4 times noise_scale, so the
    // underside has the "definition" of 000's height adjustment (lowered and
    // raised patches). 0 = a flat base.
    double base_relief = 0;
    // Own coverage: where the stencil's heights take a column (the height
    // blend w_h), its coverage is the stencil's own radial coverage
    // (coverage * g(r_c)), not the map's raised one: a tower chained after an
    // anvil sheet gets a wall the noise can billow instead of the sheet's
    // solid coverage. false = raise only (never lowers the map's).
    bool own_coverage = false;
    // Sheet heights (an anvil) instead of the radial height blend.
    bool sheet = false;
};

// The numeric options' schema (ranges, units, docs; defaults are the struct's):
// validate(), the ndf/superstorm and ndf/superstorm_anvil nodes and docs/nodes.md are
// built from it. center and seed are not numeric options.
std::span<const NumberOption<SuperstormStencil>> superstorm_options();

// Throws atlas::Error naming the parameter: an option outside its schema range or not
// finite, center not finite, min_height > max_height.
void validate(const SuperstormStencil& s);
// True when the stencil's footprint (its disc, or plume with stretch > 1)
// overlaps the map's bounds at all.
bool stencil_touches(const SuperstormStencil& s, const Box2d& bounds);
// The stencil applied to an NDF set (see the formulas above).
Field2D apply_superstorm(const Field2D& set, const SuperstormStencil& s, const MemoryBudget* budget);

// The anvil map of a stencil: channels "anvil_bias" and "anvil_lift" (m)
// over the set's grid, bias = max(previous, anvil * blend * g(r)) and lift =
// max(previous lift, anvil_lift * anvil * blend * g(r)) (previous:
// `previous`'s values, or 0 when null or when it lacks the lift channel; it
// must match the set's resolution). A renderer spreads the cloud top with
// it, as Horizon Zero Dawn's anvil bias does: the column's top rises to
// max_height + lift, and in the upper part of the column the coverage becomes
// coverage^e, e = remap(f, 0.7, 0.8, 1, lerp(1, 0.5, anvil_bias)) (f the
// height fraction; atlas/render/layer.h). Beyond the radius the previous
// values are kept exactly.
Field2D superstorm_anvil(const Field2D& set, const SuperstormStencil& s, const Field2D* previous, const MemoryBudget* budget);

// One vortex ring: an annulus [inner, outer] metres around the centre.
struct VortexRing {
    double inner, outer;  // metres, 0 <= inner < outer
    double speed;         // rotation, radians per second (falls outward)
    double skew;          // radians: tilt of the ring's spiral tendrils: the 2.5D
                          // renderer turns the ring's pattern by a further skew * phi at
                          // height fraction phi of the layer (0 base, 1 top; layer.h)
};
// N rings over [0, radius] (outer radii `radii`, strictly increasing, or
// evenly spaced when empty), each extended by `overlap` * its width into the
// next; speed_i = inner_speed * outer_0 / outer_i; skew_i = skew * i / (N-1).
// Throws on N < 1, radii not strictly increasing, radii beyond the radius.
std::vector<VortexRing> make_vortex_rings(double radius, int count, const std::vector<double>& radii, double overlap,
                                          double inner_speed, double skew);
// JSON sidecar text: {"center":[x,y],"radius":R,"overlap":o,"rings":[{"index":i,"inner":..,"outer":..,
// "overlap_end":..,"speed":..,"skew":..},..]} with overlap_end = outer + overlap * (outer - inner) (m).
std::string vortex_rings_json(Vec2d center, double radius, double overlap, const std::vector<VortexRing>& rings);
// The same table as a field the graph writes (EXR, or JSON through the `json`
// output format): N x 1 texels, channels inner, outer (m), speed (rad/s), skew
// (rad), overlap_end (m); world bounds = the square [center - radius, center +
// radius], so the bounds' centre is the storm centre and half their width the
// radius. Values are stored as float.
Field2D vortex_ring_table(Vec2d center, double radius, double overlap, const std::vector<VortexRing>& rings);
// The ring map: channels "ring_index" (index of the ring whose core holds the
// texel, -1 outside all rings) and "ring_blend" (0..1 weight of ring index+1
// in the overlap band past the ring's outer radius).
Field2D vortex_ring_map(Vec2i res, Box2d bounds, Vec2d center, const std::vector<VortexRing>& rings, double overlap,
                        const MemoryBudget* budget);

} // namespace atlas::ndf
