// Shared by the fuzz targets: the input as a file, for readers that take paths.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace atlas::fuzz {

// The per-process input file, removed when the process exits normally (libFuzzer's runs and the
// smoke runs end through exit(), so the temp directory does not fill up with one file per run).
struct InputFile {
    std::filesystem::path path;
    ~InputFile() {
        std::error_code ec;
        std::filesystem::remove(path, ec);
    }
};

// One file per process, rewritten for each input (in the temp directory).
inline std::filesystem::path input_file(const uint8_t* data, size_t size, const char* ext) {
    static const InputFile file{std::filesystem::temp_directory_path() /
                                ("atlas_fuzz_" + std::to_string(::getpid()) + ext)};
    const std::filesystem::path& path = file.path;
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    return path;
}

} // namespace atlas::fuzz
