// libFuzzer: the mesh readers. The first byte picks the format (OBJ, OFF,
// PLY, STL: the reader goes by extension), the rest is the file.
#include "atlas/core/error.h"
#include "atlas/io/geometry_files.h"
#include "atlas/volume/mesh_repair.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    static const char* ext[] = {".obj", ".off", ".ply", ".stl"};
    const auto path = std::filesystem::temp_directory_path() / ("atlas_fuzz_mesh_" + std::to_string(::getpid()) + ext[data[0] % 4]);
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size > 1 && std::fwrite(data + 1, 1, size - 1, f) != size - 1) std::abort();
    std::fclose(f);
    try {
        atlas::volume::repair_polygon_soup(atlas::io::read_polygon_soup(path));
    } catch (const atlas::Error&) {
    }
    std::filesystem::remove(path);
    return 0;
}
