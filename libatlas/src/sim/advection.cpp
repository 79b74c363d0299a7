// Semi-Lagrangian and limited MacCormack advection (see advection.h).
#include "atlas/sim/advection.h"

#include "atlas/core/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace atlas::sim {

Lattice cell_lattice(const GridSpec& s) { return {{s.nx, s.ny, s.nz}, {0.5, 0.5, 0.5}}; }
Lattice u_lattice(const GridSpec& s) { return {{s.nx + 1, s.ny, s.nz}, {0.0, 0.5, 0.5}}; }
Lattice v_lattice(const GridSpec& s) { return {{s.nx, s.ny + 1, s.nz}, {0.5, 0.0, 0.5}}; }
Lattice w_lattice(const GridSpec& s) { return {{s.nx, s.ny, s.nz + 1}, {0.5, 0.5, 0.0}}; }

namespace {

// The trilinear cell around p: base index, per-axis strides to the upper
// neighbour (0 on a single-sample axis or at the clamped upper edge) and the
// fractional weights. Positions are clamped into the lattice.
struct Corners {
    size_t base;
    size_t step[3];
    double f[3];
};

inline Corners corners(const Lattice& l, const double p[3]) {
    Corners c;
    const size_t stride[3] = {1, size_t(l.n[0]), size_t(l.n[0]) * size_t(l.n[1])};
    c.base = 0;
    for (int a = 0; a < 3; ++a) {
        const int n = l.n[a];
        if (n <= 1) {
            c.f[a] = 0;
            c.step[a] = 0;
            continue;
        }
        double x = p[a] - l.offset[a];
        x = x < 0 ? 0 : x;
        if (x >= n - 1) { // clamped at the upper edge: the last sample alone (no zero-weight neighbour)
            c.f[a] = 0;
            c.step[a] = 0;
            c.base += size_t(n - 1) * stride[a];
            continue;
        }
        const int i = int(x);
        c.f[a] = x - i;
        c.step[a] = stride[a];
        c.base += size_t(i) * stride[a];
    }
    return c;
}

inline double lerp_at(const float* q, const Corners& c) {
    const float* b = q + c.base;
    const size_t sx = c.step[0], sy = c.step[1], sz = c.step[2];
    const double fx = c.f[0], fy = c.f[1], fz = c.f[2];
    auto row = [&](const float* r) { return double(r[0]) + fx * (double(r[sx]) - double(r[0])); };
    const double c00 = row(b), c10 = row(b + sy), c01 = row(b + sz), c11 = row(b + sy + sz);
    const double c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

inline void minmax_at(const float* q, const Corners& c, float& lo, float& hi) {
    const float* b = q + c.base;
    const size_t o[8] = {0,
                         c.step[0],
                         c.step[1],
                         c.step[0] + c.step[1],
                         c.step[2],
                         c.step[0] + c.step[2],
                         c.step[1] + c.step[2],
                         c.step[0] + c.step[1] + c.step[2]};
    lo = hi = b[0];
    for (int k = 1; k < 8; ++k) {
        lo = std::min(lo, b[o[k]]);
        hi = std::max(hi, b[o[k]]);
    }
}

// Catmull-Rom weights for samples i-1, i, i+1, i+2 at fraction t.
inline void catmull_rom(double t, double w[4]) {
    const double t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t3 + 2 * t2 - t);
    w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
    w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
    w[3] = 0.5 * (t3 - t2);
}

// Tricubic Catmull-Rom read of q at p (edge indices clamped), limited to the
// min/max of the 8 trilinear corners. Axes with one sample are skipped.
float cubic_limited_at(const Lattice& l, const float* q, const double p[3]) {
    int idx[3][4];
    double w[3][4];
    int cnt[3];
    for (int a = 0; a < 3; ++a) {
        const int n = l.n[a];
        if (n <= 1) {
            cnt[a] = 1, idx[a][0] = 0, w[a][0] = 1;
            continue;
        }
        double x = p[a] - l.offset[a];
        x = x < 0 ? 0 : (x > n - 1 ? n - 1 : x);
        int i = int(x);
        if (i > n - 2) i = n - 2;
        catmull_rom(x - i, w[a]);
        cnt[a] = 4;
        for (int m = 0; m < 4; ++m) idx[a][m] = std::clamp(i - 1 + m, 0, n - 1);
    }
    const size_t sy = size_t(l.n[0]), sz = size_t(l.n[0]) * size_t(l.n[1]);
    double v = 0;
    for (int c = 0; c < cnt[2]; ++c) {
        double vy = 0;
        for (int b = 0; b < cnt[1]; ++b) {
            const float* r = q + size_t(idx[2][c]) * sz + size_t(idx[1][b]) * sy;
            double vx = 0;
            for (int a = 0; a < cnt[0]; ++a) vx += w[0][a] * double(r[idx[0][a]]);
            vy += w[1][b] * vx;
        }
        v += w[2][c] * vy;
    }
    float lo, hi;
    minmax_at(q, corners(l, p), lo, hi);
    return std::clamp(float(v), lo, hi);
}

// True when p lies within one cell of an open face (along an axis with more
// than one cell). There inflow values are read from the clamped edge, which the
// backward trace cannot invert, so the correction would be wrong. At closed
// (free-slip) faces the flow runs along the wall, both traces stay inside and
// the correction keeps its second order (falling back to semi-Lagrangian in a
// one-cell band made the whole Taylor-Green run first order in the max norm).
bool near_open_edge(const GridSpec& g, const double p[3]) {
    const int n[3] = {g.nx, g.ny, g.nz};
    for (int a = 0; a < 3; ++a) {
        if (n[a] <= 1) continue;
        if (g.face(2 * a) == Boundary::Open && p[a] < 1.0) return true;
        if (g.face(2 * a + 1) == Boundary::Open && p[a] > n[a] - 1.0) return true;
    }
    return false;
}

// Velocity (cells/s) at p on all three face lattices at once: the per-axis
// index and fraction are computed once for the face (offset 0) and the
// centre (offset 0.5) positions and shared by the components.
struct AxisPos {
    size_t i;
    double f;
    bool step; // an upper neighbour exists
};
inline AxisPos axis_pos(double x, int n) { // n samples at x = 0 .. n-1
    if (n <= 1) return {0, 0.0, false};
    x = x < 0 ? 0 : (x > n - 1 ? n - 1 : x);
    int i = int(x);
    if (i > n - 2) i = n - 2;
    return {size_t(i), x - i, true};
}
inline double lerp3(const float* q, const AxisPos& ax, const AxisPos& ay, const AxisPos& az, size_t sy, size_t sz) {
    Corners c;
    c.base = ax.i + ay.i * sy + az.i * sz;
    c.step[0] = ax.step ? 1 : 0;
    c.step[1] = ay.step ? sy : 0;
    c.step[2] = az.step ? sz : 0;
    c.f[0] = ax.f, c.f[1] = ay.f, c.f[2] = az.f;
    return lerp_at(q, c);
}
inline void velocity_fast(const MacVelocity& vel, const double p[3], double out[3]) {
    const GridSpec& g = vel.spec;
    const int nx = g.nx, ny = g.ny, nz = g.nz;
    const AxisPos fx = axis_pos(p[0], nx + 1), cx = axis_pos(p[0] - 0.5, nx);
    const AxisPos fy = axis_pos(p[1], ny + 1), cy = axis_pos(p[1] - 0.5, ny);
    const AxisPos fz = axis_pos(p[2], nz + 1), cz = axis_pos(p[2] - 0.5, nz);
    const double inv = 1.0 / g.dx;
    out[0] = nx > 1 ? lerp3(vel.u.data(), fx, cy, cz, size_t(nx + 1), size_t(nx + 1) * ny) * inv : 0.0;
    out[1] = ny > 1 ? lerp3(vel.v.data(), cx, fy, cz, size_t(nx), size_t(nx) * (ny + 1)) * inv : 0.0;
    out[2] = nz > 1 ? lerp3(vel.w.data(), cx, cy, fz, size_t(nx), size_t(nx) * ny) * inv : 0.0;
}

// Midpoint back-trace over dt from p whose velocity v0 is already known.
void trace_from(const MacVelocity& vel, const double p[3], const double v0[3], double dt, double out[3]) {
    const GridSpec& g = vel.spec;
    const double n[3] = {double(g.nx), double(g.ny), double(g.nz)};
    double mid[3], v1[3];
    for (int a = 0; a < 3; ++a) mid[a] = std::clamp(p[a] - 0.5 * dt * v0[a], 0.0, n[a]);
    velocity_fast(vel, mid, v1);
    for (int a = 0; a < 3; ++a) out[a] = std::clamp(p[a] - dt * v1[a], 0.0, n[a]);
}

template <class F>
void for_lattice(const Lattice& l, F&& f) {
    tbb::parallel_for(tbb::blocked_range<int>(0, l.n[2], 1), [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k < r.end(); ++k)
            for (int j = 0; j < l.n[1]; ++j)
                for (int i = 0; i < l.n[0]; ++i) {
                    double p[3] = {i + l.offset[0], j + l.offset[1], k + l.offset[2]};
                    f((size_t(k) * l.n[1] + j) * l.n[0] + i, p);
                }
    });
}


} // namespace

float sample_lattice(const Lattice& l, std::span<const float> q, const double p[3]) {
    return float(lerp_at(q.data(), corners(l, p)));
}

void velocity_at(const MacVelocity& vel, const double p[3], double out[3]) { velocity_fast(vel, p, out); }

void advect_many(const MacVelocity& vel, const Lattice& l, std::span<const std::span<const float>> qs,
                 std::span<const std::span<float>> outs, double dt, AdvectionScheme scheme) {
    AdvectionScratch scratch;
    advect_many(vel, l, qs, outs, dt, scheme, scratch);
}

void advect_many(const MacVelocity& vel, const Lattice& l, std::span<const std::span<const float>> qs,
                 std::span<const std::span<float>> outs, double dt, AdvectionScheme scheme, AdvectionScratch& scratch) {
    if (qs.size() != outs.size()) throw Error("sim advect: as many outputs as inputs expected");
    for (size_t f = 0; f < qs.size(); ++f)
        if (qs[f].size() != l.size() || outs[f].size() != l.size()) throw Error("sim advect: field size does not match its lattice");
    if (!std::isfinite(dt) || dt < 0) throw Error("sim advect: dt must be finite and >= 0");
    // Trace once per lattice node and reuse it for every field (and, for
    // MacCormack, for the limiter); the backward trace likewise. The scratch
    // keeps its capacity between calls (no per-step allocation).
    const bool mac = scheme == AdvectionScheme::MacCormack;
    const bool cubic = scheme == AdvectionScheme::CubicLimited;
    std::vector<float>& fwd_pos = scratch.forward;
    std::vector<float>& back_pos = scratch.backward;
    fwd_pos.resize(l.size() * 3);
    if (mac) back_pos.resize(l.size() * 3);
    for_lattice(l, [&](size_t id, const double p[3]) {
        double src[3], dst[3], v0[3];
        velocity_fast(vel, p, v0); // shared by the forward and backward traces
        trace_from(vel, p, v0, dt, src);
        for (int a = 0; a < 3; ++a) fwd_pos[id * 3 + size_t(a)] = float(src[a] - p[a]);
        if (!mac) return;
        trace_from(vel, p, v0, -dt, dst);
        for (int a = 0; a < 3; ++a) back_pos[id * 3 + size_t(a)] = float(dst[a] - p[a]);
    });
    auto pos = [&](const std::vector<float>& d, size_t id, const double p[3], double out[3]) {
        for (int a = 0; a < 3; ++a) out[a] = p[a] + double(d[id * 3 + size_t(a)]);
    };
    std::vector<float>& fwd_val = scratch.value;
    if (mac) fwd_val.resize(l.size());
    for (size_t f = 0; f < qs.size(); ++f) {
        std::span<const float> q = qs[f];
        std::span<float> out = outs[f];
        if (!mac) {
            for_lattice(l, [&](size_t id, const double p[3]) {
                double src[3];
                pos(fwd_pos, id, p, src);
                out[id] = cubic ? cubic_limited_at(l, q.data(), src) : float(lerp_at(q.data(), corners(l, src)));
            });
            continue;
        }
        for_lattice(l, [&](size_t id, const double p[3]) {
            double src[3];
            pos(fwd_pos, id, p, src);
            fwd_val[id] = float(lerp_at(q.data(), corners(l, src)));
        });
        // Backward step of the forward result, error correction and limiter in
        // one pass (reads fwd_val everywhere, writes only out[id]).
        for_lattice(l, [&](size_t id, const double p[3]) {
            double src[3];
            pos(fwd_pos, id, p, src);
            const float fv = fwd_val[id];
            if (near_open_edge(vel.spec, src)) {
                out[id] = fv; // keep semi-Lagrangian
                return;
            }
            double bsrc[3];
            pos(back_pos, id, p, bsrc);
            const float back = float(lerp_at(fwd_val.data(), corners(l, bsrc)));
            float lo, hi;
            minmax_at(q.data(), corners(l, src), lo, hi);
            const float corrected = fv + 0.5f * (q[id] - back);
            out[id] = std::clamp(corrected, lo, hi);
        });
    }
}

void advect(const MacVelocity& vel, const Lattice& l, std::span<const float> q, std::span<float> out, double dt,
            AdvectionScheme scheme) {
    std::span<const float> qs[1] = {q};
    std::span<float> outs[1] = {out};
    advect_many(vel, l, qs, outs, dt, scheme);
}

void advect_velocity(const MacVelocity& vel, MacVelocity& out, double dt, AdvectionScheme scheme) {
    AdvectionScratch scratch;
    advect_velocity(vel, out, dt, scheme, scratch);
}

void advect_velocity(const MacVelocity& vel, MacVelocity& out, double dt, AdvectionScheme scheme, AdvectionScratch& scratch) {
    const GridSpec& g = vel.spec;
    if (out.u.size() != vel.u.size() || out.v.size() != vel.v.size() || out.w.size() != vel.w.size()) out = MacVelocity(g);
    auto one = [&](const Lattice& l, const std::vector<float>& q, std::vector<float>& o) {
        std::span<const float> qs[1] = {q};
        std::span<float> os[1] = {o};
        advect_many(vel, l, qs, os, dt, scheme, scratch);
    };
    if (g.nx > 1) one(u_lattice(g), vel.u, out.u);
    if (g.ny > 1) one(v_lattice(g), vel.v, out.v);
    if (g.nz > 1) one(w_lattice(g), vel.w, out.w);
    out.enforce_walls();
}

} // namespace atlas::sim
