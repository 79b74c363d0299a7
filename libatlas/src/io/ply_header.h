// Internal: checks a PLY file's header before CGAL's reader sees it (mesh_file.cpp, point_file.cpp).
#pragma once

#include "atlas/core/files.h"

namespace atlas::io::detail {

// Throws atlas::Error naming file:line unless the header is well formed
// ('ply', a known format, properties inside elements, 'end_header'), has a
// 'vertex' element with x, y and z, with `need_faces` a 'face' element with a
// list property, and element counts the file's size can hold.
void check_ply_header(const fs::path& file, bool need_faces);

} // namespace atlas::io::detail
