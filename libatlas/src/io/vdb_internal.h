// Internal to the io module: what every VDB writer shares (vdb.cpp defines them).
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/hash.h"

#include <openvdb/openvdb.h>

#include <filesystem>

namespace atlas::io::detail {

// openvdb::initialize() once per process.
void init_openvdb();
// Index (i,j,k) -> world min + (i + 0.5) * voxel: the field's voxel centres.
// Throws what OpenVDB throws for a voxel size it cannot represent.
openvdb::math::Transform::Ptr field_transform(const Field3D& f);
// atlas_bounds_min / atlas_bounds_max / atlas_resolution metadata, which
// read_vdb uses to restore the exact field grid.
void add_atlas_meta(openvdb::GridBase& g, const Field3D& f);
// Writes the grids to `path` through a checked stream (openvdb::io::File::write
// does not check its stream: a full disk gave a truncated file and success).
// Throws atlas::Error (without a location prefix) and removes the partial file.
void write_vdb_grids(const std::filesystem::path& path, const openvdb::GridPtrVec& grids);
// Replaces OpenVDB's random archive UUID in a written file by one derived
// from `content`, so the same field gives the same bytes.
void make_uuid_deterministic(const std::filesystem::path& path, const Hash128& content);

} // namespace atlas::io::detail
