// Dispatch of the SIMD noise kernels: ATLAS_SIMD / set_simd_path, and the
// CPU's features (__builtin_cpu_supports: CPUID and the OS's AVX state).
#include "simd.h"

#include "atlas/core/error.h"

#include <atomic>
#include <cstdlib>

namespace atlas::noise {
namespace {

bool cpu_has(SimdPath p) {
    switch (p) {
    case SimdPath::Auto:
    case SimdPath::Scalar: return true;
#if defined(__x86_64__) || defined(__i386__)
#if defined(__SSE2__)
    case SimdPath::Sse2: return true;
    case SimdPath::Avx2: return __builtin_cpu_supports("avx2") != 0;
    case SimdPath::Avx512: return __builtin_cpu_supports("avx512f") != 0;
#else
    case SimdPath::Sse2:
    case SimdPath::Avx2:
    case SimdPath::Avx512: return false;
#endif
#else
    case SimdPath::Sse2:
    case SimdPath::Avx2:
    case SimdPath::Avx512: return false;
#endif
    }
    return false;
}

SimdPath fastest() {
    for (SimdPath p : {SimdPath::Avx512, SimdPath::Avx2, SimdPath::Sse2})
        if (cpu_has(p)) return p;
    return SimdPath::Scalar;
}

void require(SimdPath p, const char* where) {
    if (!cpu_has(p))
        throw Error(std::string(where) + ": the SIMD path '" + simd_path_name(p) + "' is not supported by this CPU (supported: scalar" +
                    (cpu_has(SimdPath::Sse2) ? ", sse2" : "") + (cpu_has(SimdPath::Avx2) ? ", avx2" : "") + (cpu_has(SimdPath::Avx512) ? ", avx512" : "") + ")");
}

// -1: not forced by set_simd_path.
std::atomic<int> g_forced{-1};

// ATLAS_SIMD, read once; an unknown or unsupported name is an error at every use.
struct EnvChoice {
    SimdPath path = SimdPath::Auto;
    std::string error;
};
const EnvChoice& env_choice() {
    static const EnvChoice c = [] {
        EnvChoice r;
        const char* v = std::getenv("ATLAS_SIMD");
        if (!v || !*v) return r;
        try {
            r.path = parse_simd_path(v);
            require(r.path, "ATLAS_SIMD");
        } catch (const Error& e) {
            r.error = e.what();
        }
        return r;
    }();
    return c;
}

} // namespace

std::vector<SimdPath> supported_simd_paths() {
    std::vector<SimdPath> r{SimdPath::Scalar};
    for (SimdPath p : {SimdPath::Sse2, SimdPath::Avx2, SimdPath::Avx512})
        if (cpu_has(p)) r.push_back(p);
    return r;
}

void set_simd_path(SimdPath p) {
    require(p, "set_simd_path");
    g_forced.store(p == SimdPath::Auto ? -1 : int(p));
}

SimdPath simd_path() {
    const int f = g_forced.load();
    if (f >= 0) return SimdPath(f);
    const EnvChoice& e = env_choice();
    if (!e.error.empty()) throw Error(e.error);
    return e.path == SimdPath::Auto ? fastest() : e.path;
}

const char* simd_path_name(SimdPath p) {
    switch (p) {
    case SimdPath::Auto: return "auto";
    case SimdPath::Scalar: return "scalar";
    case SimdPath::Sse2: return "sse2";
    case SimdPath::Avx2: return "avx2";
    case SimdPath::Avx512: return "avx512";
    }
    return "?";
}

SimdPath parse_simd_path(const std::string& name) {
    for (SimdPath p : {SimdPath::Auto, SimdPath::Scalar, SimdPath::Sse2, SimdPath::Avx2, SimdPath::Avx512})
        if (name == simd_path_name(p)) return p;
    throw Error("unknown SIMD path '" + name + "' (expected auto, scalar, sse2, avx2 or avx512)");
}

namespace detail {

const SimdKernels* active_kernels() {
    switch (simd_path()) {
#if defined(__SSE2__)
    case SimdPath::Sse2: return &sse2_kernels();
    case SimdPath::Avx2: return &avx2_kernels();
    case SimdPath::Avx512: return &avx512_kernels();
#endif
    default: return nullptr;
    }
}

} // namespace detail
} // namespace atlas::noise
