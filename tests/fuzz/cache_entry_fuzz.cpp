// libFuzzer: on-disk cache entries. A damaged entry is a miss (nullopt), never
// a crash, a hang or an allocation the entry's size does not justify.
#include "value_cache.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    std::string why;
    atlas::disk_cache::deserialize(bytes, &why);
    return 0;
}
