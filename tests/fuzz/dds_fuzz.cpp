// libFuzzer: DDS files (headers, DX10 extension, BC and uncompressed payloads).
#include "atlas/io/dds_file.h"
#include "atlas/core/error.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto path = atlas::fuzz::input_file(data, size, ".dds");
    try {
        atlas::io::read_dds_file(path);
    } catch (const atlas::Error&) {
    }
    return 0;
}
