// Instruction-set paths of the noise kernels. Every path writes the same
// bytes (docs/noise.md, "SIMD"); choosing one changes only the speed.
#pragma once

#include <string>
#include <vector>

namespace atlas::noise {

enum class SimdPath { Auto, Scalar, Sse2, Avx2, Avx512 };

// The paths this machine can run, scalar first.
std::vector<SimdPath> supported_simd_paths();

// Forces a path for every later fill in this process (Auto: the fastest
// supported, unless the environment variable ATLAS_SIMD=scalar|sse2|avx2|avx512|auto
// names one). Throws atlas::Error for a path the machine lacks.
void set_simd_path(SimdPath p);

// The path fills use now (never Auto). Throws atlas::Error when ATLAS_SIMD
// holds an unknown name or a path the machine lacks.
SimdPath simd_path();

const char* simd_path_name(SimdPath p);
SimdPath parse_simd_path(const std::string& name); // throws atlas::Error

} // namespace atlas::noise
