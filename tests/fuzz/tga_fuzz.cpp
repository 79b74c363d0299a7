// libFuzzer: the TGA codec (Nubis pack slices): raw and RLE, types 2, 3, 10, 11.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/io/tga_slices.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const atlas::MemoryBudget budget(64ull << 20);
    const auto path = atlas::fuzz::input_file(data, size, ".tga");
    try {
        atlas::io::read_tga(path, &budget);
    } catch (const atlas::Error&) {
    }
    return 0;
}
