// Internal: whether the BC encoders may take their AVX2 paths. The CPU decides, unless
// ATLAS_SIMD (the noise kernels' switch, docs/noise.md "SIMD") asks for `scalar` or `sse2`:
// then the portable paths run on any machine, so that a cluster of mixed CPUs can be
// checked for the same bytes (issue 46 item 4; the bytes do not depend on the path).
#pragma once

#include <cstdlib>
#include <cstring>

namespace atlas::compress::detail {

inline bool simd_env_forbids_avx2() {
    static const bool no = [] {
        const char* v = std::getenv("ATLAS_SIMD");
        return v && (std::strcmp(v, "scalar") == 0 || std::strcmp(v, "sse2") == 0);
    }();
    return no;
}

} // namespace atlas::compress::detail
