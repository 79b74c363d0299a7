// atlas/io/geometry_files.h - mesh and point-cloud files.
//
// Meshes: OBJ and OFF are parsed here (every error names file:line, the vertex
// or face, and what was expected); PLY and STL go through CGAL::IO after their
// headers are checked against the file's size (CGAL's readers trust them).
// Points: PLY through CGAL, XYZ text here. Coordinates are taken as metres.
// Only regular files are read (a device or FIFO is refused before reading).
// Thread-safety: safe to call concurrently on distinct files.
//
// Implemented in mesh_file.cpp, point_file.cpp (src/io/).
#pragma once

#include "atlas/core/files.h"
#include "atlas/core/geometry.h"

namespace atlas::io {

// Reads OBJ, OFF, PLY or STL (by extension, case-insensitive) as the file
// holds it: no repair (volume::repair_polygon_soup makes a voxelisable mesh).
// Throws atlas::Error naming the file when it cannot be read, has no faces, or
// fails validate_polygon_soup.
PolygonSoup read_polygon_soup(const fs::path& file);

// Writes a mesh through CGAL::IO (format by extension: obj, off, ply, stl; 9
// significant digits). Throws atlas::Error when the file cannot be written.
void write_mesh(const fs::path& file, const Mesh& mesh);

// Reads a point cloud: PLY (through CGAL; float properties such as "radius"
// become attributes) or XYZ text ("x y z [radius [weight]]" per line, '#'
// comments; also .txt, .pts). Throws atlas::Error naming the file and line on
// bad input.
Points read_points(const fs::path& file);

} // namespace atlas::io
