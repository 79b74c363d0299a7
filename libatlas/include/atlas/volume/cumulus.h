// atlas/volume/cumulus.h - cumulus anatomy from coarse shapes (issue 41).
//
// A coarse shape (a few metaballs, points, an interior fill) is smooth at
// one scale: splatted and turned into a profile it reads as cotton balls.
// Real cumulus (the Nubis pack's two clouds, docs/look.md) has lobes of
// 25-80 m on lobes, facing up and out, towers where the shape rises, a flat
// base at the condensation height with a thin skirt, billowy detail on the
// tops and wispy detail below. Two steps give it:
//   billow_spheres  adds generations of smaller spheres on the exposed,
//                   up- and out-facing surface of the shape, and towers
//                   (stacks of tapering spheres) on its highest spheres, in
//                   the manner of Houdini's Cloud Shape Replicate;
//   cumulus_channels paints detail type and density scale from the cloud's
//                   SDF as the pack has them: detail type 1 on up-facing
//                   surfaces fading to 0 some 60 m below them and on
//                   undersides; density scale 0 at the base rising to 1.
// Deterministic (hash_coords only), thread-count independent.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/geometry.h"

namespace atlas {
class MemoryBudget;
}

namespace atlas::volume {

struct BillowSpec {
    int levels = 2;            // generations of smaller spheres (0: the shape as it is)
    int children = 10;         // spheres tried per sphere of the previous generation
    double ratio = 0.45;       // child radius / parent radius
    double jitter = 0.3;       // relative spread of child radii (0..1)
    double up_bias = 0.6;      // 0: children all round; 1: all on the upper half
    double min_up = -0.3;      // no child where the direction's z is below this (undersides stay smooth)
    double sink = 0.75;        // child centre at this fraction of the parent radius from its centre
    double min_radius = 8;     // metres: smaller children are not made (a voxel or two)
    double base_height = -1e9; // metres: no child below the condensation height
    int towers = 0;            // stacks of spheres rising from the highest spheres
    double tower_height = 200; // metres a tower rises above its sphere's top
    double tower_taper = 0.85; // radius ratio from one tower sphere to the next
    double tower_lean = 0.15;  // lateral drift per step, in radii
    uint32_t seed = 1;
};

// The shape's spheres (positions and attribute 'radius', metres), then the
// towers, then each generation of billows. A child is kept only where its
// outer tip is not inside another sphere (billows grow on the exposed
// surface). Throws atlas::Error on bad settings or a shape without radii.
Points billow_spheres(const Points& shape, const BillowSpec& spec);

struct SphereFillSpec {
    double min_radius = 16;   // metres: thinner parts get no sphere of their own
    double max_radius = 1e9;  // metres: larger inscribed balls are capped (a tall tower becomes a stack)
    double cover = 0.7;       // a sphere claims the voxels within this fraction of its radius
    int max_spheres = 4096;
};

// Spheres that fill a shape given as an SDF (negative inside): the deepest
// uncovered voxel first, its inscribed ball (radius -sdf, capped), until every
// voxel at least min_radius deep is claimed. Turns a solver's cloud, a mesh or
// any field into the coarse spheres billow_spheres grows (issue 41: solver to
// cloud). Points with attribute 'radius'. Deterministic (ties by voxel index).
Points spheres_from_sdf(const Field3D& sdf, const SphereFillSpec& spec);

struct CumulusPaintSpec {
    double base_height = 0;     // metres: the condensation height (flat base)
    double billow_depth = 200;  // metres below an up-facing surface where detail type reaches 0
    // The pack's density scale is low (median 0.24-0.31 over its clouds,
    // rising with height); its facing values, about -0.2 / 0.7 (sides 0.3),
    // shred the sides under Atlas's preview up-rez (256 m noise tiles), so the
    // sides stay billowy. Billows reach 200 m in: a wispy core under a soft
    // profile ramp is eroded away (docs/look.md).
    double facing_low = -0.9;   // upward component of the surface normal where detail type starts
    double facing_high = 0.2;   // ... and where it is full
    double skirt = 40;          // metres above the base kept wispy (detail type 0)
    double scale_floor = 0.2;   // density scale at the base
    double scale_ramp = 500;    // metres over which density scale rises to 1
    // Voxels whose SDF is more than this many voxels (the largest voxel side) outside the
    // cloud get 0 in both channels: no sample reads them (a sample inside the cloud
    // blends taps at most a voxel diagonal away), and constant space compresses to flat
    // texture blocks and sparse VDB grids. A huge value paints everywhere.
    double outside_voxels = 3;
};

struct CumulusChannels {
    Field3D detail_type;
    Field3D density_scale;
};

// Detail type and density scale on the SDF's grid (one channel each, named
// so), defined everywhere (also outside the cloud, so that filtering at the
// edge reads the cloud's values). Throws atlas::Error on bad settings.
// `frame`: the SDF's place in the grid it is a window of (a tiled cook's
// crop grown by one voxel); null: its own grid.
CumulusChannels cumulus_channels(const Field3D& sdf, const CumulusPaintSpec& spec, const MemoryBudget* budget = nullptr,
                                 const GridFrame* frame = nullptr);

} // namespace atlas::volume
