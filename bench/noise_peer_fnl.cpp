// The FastNoiseLite peer of noise_bench (docs/PERFORMANCE.md): compiled only
// when ATLAS_PEERS_DIR holds FastNoiseLite.h (not part of Atlas), with
// -O3 -march=native as its users build it. Same sampling as Atlas's fill:
// voxel centres of an n^3 grid, `cells` lattice cells along each axis, one
// octave, one thread.
#include <FastNoiseLite.h>

namespace atlas_peer {

// kind 0: 3D Perlin; 1: 3D cellular (Euclidean F1, jitter 1).
void fnl_fill(int kind, int n, int cells, int seed, float* out) {
    FastNoiseLite noise(seed);
    noise.SetFrequency(1.0f);
    if (kind == 0) {
        noise.SetNoiseType(FastNoiseLite::NoiseType_Perlin);
    } else {
        noise.SetNoiseType(FastNoiseLite::NoiseType_Cellular);
        noise.SetCellularDistanceFunction(FastNoiseLite::CellularDistanceFunction_Euclidean);
        noise.SetCellularReturnType(FastNoiseLite::CellularReturnType_Distance);
        noise.SetCellularJitter(1.0f);
    }
    const float s = float(cells) / float(n);
    size_t i = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) out[i++] = noise.GetNoise((float(x) + 0.5f) * s, (float(y) + 0.5f) * s, (float(z) + 0.5f) * s);
}

} // namespace atlas_peer
