// The FastNoise2 peer of noise_bench (docs/PERFORMANCE.md): a standalone
// program that bench/compare_fastnoise2.sh builds against a FastNoise2 checkout
// outside the repository (never part of Atlas's build). FastNoise2's own
// entry point, GenUniformGrid3D, fills a 128^3 grid, one thread, at each SIMD
// level it dispatches to: Perlin and CellularDistance (its defaults: Euclidean
// F1, jitter 1). Median of 7 fills.
#include <FastNoise/FastNoise.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>
int main() {
    const int n = 128;
    std::vector<float> out(size_t(n) * n * n);
    struct L { const char* name; FastSIMD::FeatureSet f; } levels[] = {{"sse2", FastSIMD::FeatureSet::SSE2}, {"avx2", FastSIMD::FeatureSet::AVX2}, {"avx512", FastSIMD::FeatureSet::AVX512}};
    for (auto& l : levels) {
        for (int k = 0; k < 2; ++k) {
            FastNoise::SmartNode<FastNoise::Generator> g;
            if (k == 0) g = FastNoise::New<FastNoise::Perlin>(l.f);
            else g = FastNoise::New<FastNoise::CellularDistance>(l.f);
            std::vector<double> t;
            for (int r = 0; r < 7; ++r) {
                auto a = std::chrono::steady_clock::now();
                g->GenUniformGrid3D(out.data(), 0, 0, 0, n, n, n, 1.0f / 16, 1.0f / 16, 1.0f / 16, 1337);
                t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
            }
            std::sort(t.begin(), t.end());
            std::printf("FastNoise2 %-6s %-8s %.1f M samples/s (median of 7, %.2f ms)\n", l.name, k ? "cellular" : "perlin", double(out.size()) / t[3] / 1e6, t[3] * 1e3);
        }
    }
}
