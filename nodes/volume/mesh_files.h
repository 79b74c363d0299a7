// Shared by volume/read_mesh and the tests (not a node): a mesh file read by io
// and repaired by volume, with repair errors naming the file.
#pragma once

#include "atlas/core/error.h"
#include "atlas/io/geometry_files.h"
#include "atlas/volume/mesh_repair.h"

namespace atlas::volume_nodes {

inline Mesh read_mesh_file(const fs::path& file, volume::MeshRepairReport* report = nullptr) {
    PolygonSoup soup = io::read_polygon_soup(file);
    try {
        return volume::repair_polygon_soup(std::move(soup), report);
    } catch (const Error& e) {
        throw Error(file.string() + ": " + e.what());
    }
}

} // namespace atlas::volume_nodes
