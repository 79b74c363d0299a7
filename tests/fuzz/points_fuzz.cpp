// libFuzzer: the point file readers. The first byte picks the format (PLY or
// XYZ text), the rest is the file.
#include "atlas/core/error.h"
#include "atlas/io/geometry_files.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    static const char* ext[] = {".ply", ".xyz"};
    const auto path = std::filesystem::temp_directory_path() / ("atlas_fuzz_points_" + std::to_string(::getpid()) + ext[data[0] % 2]);
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size > 1 && std::fwrite(data + 1, 1, size - 1, f) != size - 1) std::abort();
    std::fclose(f);
    try {
        atlas::io::read_points(path);
    } catch (const atlas::Error&) {
    }
    std::filesystem::remove(path);
    return 0;
}
