// libFuzzer: the EXR reader (Atlas's 3D slice stacks and foreign 2D images).
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/io/exr.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const atlas::MemoryBudget budget(64ull << 20);
    const auto path = atlas::fuzz::input_file(data, size, ".exr");
    try {
        atlas::io::read_exr(path, &budget);
    } catch (const atlas::Error&) {
    }
    return 0;
}
