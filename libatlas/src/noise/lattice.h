// Internal: the wrapped integer lattice every kernel samples, and the 64
// random bits attached to each lattice point.
#pragma once

#include "atlas/core/hash.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace atlas::noise::detail {

template <int D>
using IVec = std::array<int, D>;

// High 32 bits: hash_coords itself (so value noise matches value_noise()),
// low 32 bits: a remix of them (offsets, magnitudes).
inline uint64_t lattice_bits_of(uint32_t h) { return (uint64_t(h) << 32) | (mix64(h) & 0xFFFFFFFFull); }
inline uint64_t lattice_bits(uint32_t seed, uint32_t stream, int x, int y, int z) { return lattice_bits_of(hash_coords(seed, x, y, z, stream)); }

// lattice_bits(seed, stream, x, y, z) & mask for a cell's corners x in xs,
// y in ys, z in zs, into out[i + 2j + 4k], from x = xs[first_i] on (1: the
// x0 face is the caller's); hash_coords' chain is shared by corners with a
// common prefix: 2 + 4 + 8 x 3 mixes instead of 8 x 6.
inline void corner_bits3(uint32_t seed, uint32_t stream, const int (&xs)[2], const int (&ys)[2], const int (&zs)[2], uint32_t mask,
                         int first_i, int (&out)[8]) {
    const uint64_t h0 = hash_begin(seed);
    for (int i = first_i; i < 2; ++i) {
        const uint64_t hx = hash_step_x(h0, xs[i]);
        for (int j = 0; j < 2; ++j) {
            const uint64_t hxy = hash_step_y(hx, ys[j]);
            for (int k = 0; k < 2; ++k) {
                out[i + 2 * j + 4 * k] = int(lattice_bits_of(hash_end(hash_step_z(hxy, zs[k]), stream)) & mask);
            }
        }
    }
}

// Lattices up to this many points are tabulated once (8 bytes each): a
// lookup is then a load instead of six 64-bit mixes. Larger (high-octave)
// lattices hash on the fly; both give the same bits.
inline constexpr int64_t kMaxTablePoints = int64_t(1) << 21;

template <int D>
class Lattice {
public:
    // Tabulates when the lattice has at most max_table_points points (0: never).
    Lattice(IVec<D> period, uint32_t seed, uint32_t stream, int64_t max_table_points) : period_(period), seed_(seed), stream_(stream) {
        int64_t n = 1;
        for (int p : period) n *= p;
        if (n > std::min(max_table_points, kMaxTablePoints)) return;
        table_.resize(size_t(n));
        size_t i = 0;
        const int pz = D == 3 ? period[D - 1] : 1;
        for (int z = 0; z < pz; ++z)
            for (int y = 0; y < period[1]; ++y)
                for (int x = 0; x < period[0]; ++x) table_[i++] = lattice_bits(seed, stream, x, y, z);
    }
    const IVec<D>& period() const { return period_; }
    uint32_t seed() const { return seed_; }
    uint32_t stream() const { return stream_; }
    // The tabulated bits (x fastest), or nullptr when they are hashed on the fly.
    const uint64_t* table() const { return table_.empty() ? nullptr : table_.data(); }
    // c must be wrapped into [0, period).
    uint64_t bits(int x, int y, int z = 0) const {
        if (!table_.empty()) {
            size_t i = size_t(x) + size_t(period_[0]) * (size_t(y) + (D == 3 ? size_t(period_[1]) * size_t(z) : 0));
            return table_[i];
        }
        return lattice_bits(seed_, stream_, x, y, z);
    }

private:
    IVec<D> period_;
    uint32_t seed_;
    uint32_t stream_;
    std::vector<uint64_t> table_;
};

// One coordinate split into its wrapped cell and the fraction inside it.
struct Split {
    int cell;   // [0, period)
    int next;   // cell + 1 wrapped
    int prev;   // cell - 1 wrapped
    float frac; // [0, 1]
};

// u must lie in [0, period]; callers wrap coordinates with wrap_coord first.
inline Split split(double u, int period) {
    const double fl = std::floor(u);
    int c = int(fl);
    const float f = float(u - fl);
    if (c >= period) c -= period; // u == period after rounding
    if (c < 0) c = 0;
    return {c, c + 1 == period ? 0 : c + 1, c == 0 ? period - 1 : c - 1, f};
}

// Reduces a lattice coordinate into [0, period). Exact enough that x and
// x + period give the same result to within a few ulps of x.
inline double wrap_coord(double u, double period) {
    double r = u - period * std::floor(u / period);
    if (r >= period) r -= period;
    if (r < 0) r = 0;
    return r;
}

// Unit-cell offsets from lattice bits (16 bits each).
inline float bits_unit16(uint64_t b, int field) { return float((b >> (16 * field)) & 0xFFFFu) * (1.0f / 65536.0f); }

} // namespace atlas::noise::detail
