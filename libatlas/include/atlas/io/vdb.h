// atlas/io/vdb.h - OpenVDB files: dense Field3D <-> sparse float/vector grids.
//
// Field voxel (i, j, k) is VDB voxel (i, j, k); the grid transform is linear
// (scale by the voxel size per axis, translate by bounds.min + half a voxel),
// so voxel centres coincide. The field's bounds are also stored as grid
// metadata (atlas_bounds_min / atlas_bounds_max) so a round trip restores
// them exactly even when the border is empty.
// Grids are fog volumes (GRID_FOG_VOLUME) with background 0.
// Output bytes are deterministic: the archive's random UUID is replaced by
// one derived from the field's content hash and the options.
// openvdb::initialize() is called once internally. Thread-safe for distinct files.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <filesystem>
#include <string>
#include <vector>

namespace atlas::io {

namespace fs = std::filesystem;

struct VdbOptions {
    std::vector<std::string> grid_names; // default: the field's channel names
    float tolerance = 0.0f;              // |v - 0| <= tolerance is left inactive (background 0); finite, >= 0
    bool vector3 = false;                // write 3 channels as one Vec3s grid, named after the channels'
                                         // shared "NAME." prefix (vel.x/.y/.z -> vel) or "vector"
};

// Throws atlas::Error naming the file on a bad option (grid name count,
// duplicate names, negative tolerance, vector3 without 3 channels) or I/O failure.
void write_vdb(const Field3D& field, const fs::path& path, const VdbOptions& options = {});

// Names of the grids in a file (any type).
std::vector<std::string> list_vdb_grids(const fs::path& path);

// Reads the named float grids (or every float and vec3s grid when empty; a
// vec3s grid becomes 3 channels "name.x/.y/.z") densified over the atlas
// bounds metadata when present and consistent with the transform (exact round
// trip), else over the union of their active bounding boxes (bounds = that
// box's outer voxel faces). Inactive voxels read as each grid's background.
// Grids must share one axis-aligned linear transform with positive voxel
// sizes. Throws atlas::Error naming the file: missing grid (listing those
// present), non-float grid, no active voxels, different transforms,
// rotated/frustum transforms, unreadable or truncated file.
Field3D read_vdb(const fs::path& path, const std::vector<std::string>& grid_names = {}, const MemoryBudget* budget = nullptr);

} // namespace atlas::io
