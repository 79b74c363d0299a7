// Internal: checks a PLY file's header before CGAL's reader sees it (mesh_io.cpp).
#pragma once

#include <filesystem>

namespace atlas::volume::detail {

// Throws atlas::Error naming file:line unless the header is well formed
// ('ply', a known format, properties inside elements, 'end_header'), has a
// 'vertex' element with x, y and z, with `need_faces` a 'face' element with a
// list property, and element counts the file's size can hold.
void check_ply_header(const std::filesystem::path& file, bool need_faces);

} // namespace atlas::volume::detail
