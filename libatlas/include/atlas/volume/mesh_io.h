// atlas/volume/mesh_io.h - reading, checking and repairing triangle meshes.
//
// Files are read through CGAL::IO (OBJ, OFF, PLY, STL, chosen by extension),
// then repaired (repair_mesh below). Units: the file's coordinates are taken
// as metres. Thread-safety: pure functions, safe to call concurrently.
#pragma once

#include "atlas/core/geometry.h"

#include <cstdint>
#include <filesystem>

namespace atlas::volume {

// What repair_mesh changed, for the cook report.
struct MeshRepairReport {
    uint64_t merged_vertices = 0;      // duplicate positions merged
    uint64_t removed_degenerate = 0;   // triangles with repeated or collinear corners
    uint64_t removed_duplicates = 0;   // triangles repeating another (any orientation)
    uint64_t flipped_triangles = 0;    // triangles turned to agree with their neighbours / face outwards
    uint64_t polygons_triangulated = 0; // faces with more than 3 corners fan-triangulated (files only)
    uint64_t components = 0;           // edge-connected components after repair
};

// Largest |coordinate| (metres) of a vertex or a grid bound. Distances then
// stay below ~3.5e18 m; beyond ~1.8e19 m their squares overflow float.
inline constexpr double kMaxMeshCoordinate = 1e18;

// Throws atlas::Error (naming `who` and the problem) when the mesh has no
// triangles, a vertex that is NaN or infinite or beyond +-kMaxMeshCoordinate
// (naming its index and coordinate), or an index out of range.
void validate_mesh(const Mesh& mesh, const char* who = "mesh");

// Repair for voxelisation: merge duplicate vertices (exact positions), drop
// degenerate triangles (repeated corners, or area below 1e-12 of the bounding
// box diagonal squared) and duplicate triangles, make orientation consistent
// across shared edges (CGAL::Polygon_mesh_processing::orient_polygon_soup),
// then flip each edge-connected component whose signed volume (about its
// own centroid) is negative so that normals face outwards.
// Validates first (see validate_mesh). Deterministic.
Mesh repair_mesh(const Mesh& mesh, MeshRepairReport* report = nullptr);

// Reads OBJ, OFF, PLY or STL (by extension, case-insensitive) through
// CGAL::IO and repairs it. Throws atlas::Error naming the file when it cannot
// be read, has no faces, or holds a non-finite coordinate.
Mesh read_mesh(const std::filesystem::path& file, MeshRepairReport* report = nullptr);

// Writes a mesh through CGAL::IO (format by extension: obj, off, ply, stl).
// Throws atlas::Error when the file cannot be written.
void write_mesh(const std::filesystem::path& file, const Mesh& mesh);

} // namespace atlas::volume
