// libFuzzer: the VDB reader, behind its own header and descriptor check.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/io/vdb.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const atlas::MemoryBudget budget(64ull << 20);
    const auto path = atlas::fuzz::input_file(data, size, ".vdb");
    try {
        atlas::io::read_vdb(path, {}, &budget);
    } catch (const atlas::Error&) {
    }
    return 0;
}
