// Internal: value noise (quintic blend of lattice values in [0, 1)); the same
// lattice values as atlas::noise::value_noise().
#pragma once

#include "gradient.h"

namespace atlas::noise::detail {

inline float lattice_value(uint64_t bits) { return hash_to_unit(uint32_t(bits >> 32)); }

inline float value3(const Lattice<3>& L, const Split& sx, const Split& sy, const Split& sz) {
    const float u = fade(sx.frac), v = fade(sy.frac), w = fade(sz.frac);
    auto at = [&](int x, int y, int z) { return lattice_value(L.bits(x, y, z)); };
    const float c00 = at(sx.cell, sy.cell, sz.cell) + u * (at(sx.next, sy.cell, sz.cell) - at(sx.cell, sy.cell, sz.cell));
    const float c10 = at(sx.cell, sy.next, sz.cell) + u * (at(sx.next, sy.next, sz.cell) - at(sx.cell, sy.next, sz.cell));
    const float c01 = at(sx.cell, sy.cell, sz.next) + u * (at(sx.next, sy.cell, sz.next) - at(sx.cell, sy.cell, sz.next));
    const float c11 = at(sx.cell, sy.next, sz.next) + u * (at(sx.next, sy.next, sz.next) - at(sx.cell, sy.next, sz.next));
    const float y0 = c00 + v * (c10 - c00), y1 = c01 + v * (c11 - c01);
    return y0 + w * (y1 - y0);
}

inline float value2(const Lattice<2>& L, const Split& sx, const Split& sy) {
    const float u = fade(sx.frac), v = fade(sy.frac);
    auto at = [&](int x, int y) { return lattice_value(L.bits(x, y)); };
    const float c0 = at(sx.cell, sy.cell) + u * (at(sx.next, sy.cell) - at(sx.cell, sy.cell));
    const float c1 = at(sx.cell, sy.next) + u * (at(sx.next, sy.next) - at(sx.cell, sy.next));
    return c0 + v * (c1 - c0);
}

} // namespace atlas::noise::detail
