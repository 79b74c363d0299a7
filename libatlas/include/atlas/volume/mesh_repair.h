// atlas/volume/mesh_repair.h - checking and repairing triangle meshes.
//
// Meshes come from graphs or from files read by io (atlas/io/geometry_files.h:
// io::read_polygon_soup), then are repaired here for voxelisation. Units:
// metres. Thread-safety: pure functions, safe to call concurrently.
#pragma once

#include "atlas/core/geometry.h"

#include <cstdint>

namespace atlas::volume {

// What the repair changed, for the cook report.
struct MeshRepairReport {
    uint64_t merged_vertices = 0;      // duplicate positions merged
    uint64_t removed_degenerate = 0;   // triangles with repeated or collinear corners
    uint64_t removed_duplicates = 0;   // triangles repeating another (any orientation)
    uint64_t flipped_triangles = 0;    // triangles turned to agree with their neighbours / face outwards
    uint64_t polygons_triangulated = 0; // faces with more than 3 corners fan-triangulated (soups only)
    uint64_t components = 0;           // edge-connected components after repair
};

using atlas::kMaxMeshCoordinate; // core/geometry.h: the largest |coordinate| accepted

// validate_mesh lives beside validate_polygon_soup (core/geometry.h): no
// triangles, a NaN, infinite or beyond +-kMaxMeshCoordinate vertex, or an
// index out of range throws atlas::Error naming `who` and the problem.
using atlas::validate_mesh;

// Repair for voxelisation: merge duplicate vertices (exact positions), drop
// degenerate triangles (repeated corners, or area below 1e-12 of the bounding
// box diagonal squared) and duplicate triangles, make orientation consistent
// across shared edges (CGAL::Polygon_mesh_processing::orient_polygon_soup),
// then flip each edge-connected component whose signed volume (about its
// own centroid) is negative so that normals face outwards.
// Validates first (see validate_mesh). Deterministic.
Mesh repair_mesh(const Mesh& mesh, MeshRepairReport* report = nullptr);

// The same repair for a polygon soup (a mesh file's contents): polygons with
// more than 3 corners are fan-triangulated first. Validates the soup
// (validate_polygon_soup); throws atlas::Error "mesh: ..." when no usable
// triangle remains.
Mesh repair_polygon_soup(PolygonSoup soup, MeshRepairReport* report = nullptr);

} // namespace atlas::volume
