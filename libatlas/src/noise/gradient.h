// Internal: Perlin gradient noise (improved, quintic fade) in 2D and 3D, with
// analytic derivatives for curl noise.
#pragma once

#include "lattice.h"

namespace atlas::noise::detail {

inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
inline float dfade(float t) { return 30.0f * t * t * (t * (t - 2.0f) + 1.0f); }

// 3D: the 12 cube-edge directions, 4 repeated to make 16 (Perlin 2002).
inline constexpr float kGrad3[16][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                        {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1},
                                        {1, 1, 0}, {-1, 1, 0}, {0, -1, 1}, {0, -1, -1}};
// 2D: 8 unit directions at 45 degree steps.
inline constexpr float kS = 0.70710678f;
inline constexpr float kGrad2[8][2] = {{1, 0}, {kS, kS}, {0, 1}, {-kS, kS}, {-1, 0}, {-kS, -kS}, {0, -1}, {kS, -kS}};
// Scales the 2D signal to about [-1, 1] (unit gradients peak near 1/sqrt 2).
inline constexpr float kGrad2Scale = 1.41421356f;

// The 8 corner gradients of one cell; reloaded only when the cell changes
// (consecutive samples of a row mostly share a cell).
struct GradCache3 {
    int cx = -1, cy = -1, cz = -1;
    float g[8][3];

    void load(const Lattice<3>& L, const Split& sx, const Split& sy, const Split& sz) {
        if (sx.cell == cx && sy.cell == cy && sz.cell == cz) return;
        cx = sx.cell;
        cy = sy.cell;
        cz = sz.cell;
        const int xs[2] = {sx.cell, sx.next}, ys[2] = {sy.cell, sy.next}, zs[2] = {sz.cell, sz.next};
        int idx[8];
        if (L.table())
            for (int c = 0; c < 8; ++c) idx[c] = int(L.bits(xs[c & 1], ys[(c >> 1) & 1], zs[c >> 2]) & 15u);
        else
            corner_bits3(L.seed(), L.stream(), xs, ys, zs, 15u, 0, idx);
        for (int c = 0; c < 8; ++c) {
            const float* gr = kGrad3[idx[c]];
            g[c][0] = gr[0];
            g[c][1] = gr[1];
            g[c][2] = gr[2];
        }
    }
};

// Value in about [-1, 1] (not clamped); d (optional) receives d/du, d/dv, d/dw
// in units per lattice cell.
inline float gradient3(const GradCache3& gc, float fx, float fy, float fz, float* d) {
    const float u = fade(fx), v = fade(fy), w = fade(fz);
    float n[8];
    for (int c = 0; c < 8; ++c) {
        const int i = c & 1, j = (c >> 1) & 1, k = c >> 2;
        n[c] = gc.g[c][0] * (fx - float(i)) + gc.g[c][1] * (fy - float(j)) + gc.g[c][2] * (fz - float(k));
    }
    // Trilinear blend with the faded weights.
    const float x00 = n[0] + u * (n[1] - n[0]), x10 = n[2] + u * (n[3] - n[2]), x01 = n[4] + u * (n[5] - n[4]), x11 = n[6] + u * (n[7] - n[6]);
    const float y0 = x00 + v * (x10 - x00), y1 = x01 + v * (x11 - x01);
    const float value = y0 + w * (y1 - y0);
    if (d) {
        const float du = dfade(fx), dv = dfade(fy), dw = dfade(fz);
        float dx = 0, dy = 0, dz = 0;
        for (int c = 0; c < 8; ++c) {
            const int i = c & 1, j = (c >> 1) & 1, k = c >> 2;
            const float wx = i ? u : 1 - u, wy = j ? v : 1 - v, wz = k ? w : 1 - w;
            const float dwx = i ? du : -du, dwy = j ? dv : -dv, dwz = k ? dw : -dw;
            dx += dwx * wy * wz * n[c] + wx * wy * wz * gc.g[c][0];
            dy += wx * dwy * wz * n[c] + wx * wy * wz * gc.g[c][1];
            dz += wx * wy * dwz * n[c] + wx * wy * wz * gc.g[c][2];
        }
        d[0] = dx;
        d[1] = dy;
        d[2] = dz;
    }
    return value;
}

inline float gradient2(const Lattice<2>& L, const Split& sx, const Split& sy, float* d) {
    const float fx = sx.frac, fy = sy.frac;
    const float u = fade(fx), v = fade(fy);
    float n[4];
    float g[4][2];
    const int xs[2] = {sx.cell, sx.next}, ys[2] = {sy.cell, sy.next};
    for (int c = 0; c < 4; ++c) {
        const int i = c & 1, j = c >> 1;
        const float* gr = kGrad2[L.bits(xs[i], ys[j]) & 7u];
        g[c][0] = gr[0] * kGrad2Scale;
        g[c][1] = gr[1] * kGrad2Scale;
        n[c] = g[c][0] * (fx - float(i)) + g[c][1] * (fy - float(j));
    }
    const float x0 = n[0] + u * (n[1] - n[0]), x1 = n[2] + u * (n[3] - n[2]);
    const float value = x0 + v * (x1 - x0);
    if (d) {
        const float du = dfade(fx), dv = dfade(fy);
        float dx = 0, dy = 0;
        for (int c = 0; c < 4; ++c) {
            const int i = c & 1, j = c >> 1;
            const float wx = i ? u : 1 - u, wy = j ? v : 1 - v;
            const float dwx = i ? du : -du, dwy = j ? dv : -dv;
            dx += dwx * wy * n[c] + wx * wy * g[c][0];
            dy += wx * dwy * n[c] + wx * wy * g[c][1];
        }
        d[0] = dx;
        d[1] = dy;
    }
    return value;
}

} // namespace atlas::noise::detail
