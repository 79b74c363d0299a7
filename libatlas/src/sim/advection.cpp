// Semi-Lagrangian and limited MacCormack advection (see advection.h).
#include "atlas/sim/advection.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace atlas::sim {

namespace {
Lattice with_period(Lattice l, const GridSpec& s) {
    l.period[0] = s.periodic(0) ? s.nx : 0;
    l.period[1] = s.periodic(1) ? s.ny : 0;
    return l;
}
} // namespace

Lattice cell_lattice(const GridSpec& s) { return with_period({{s.nx, s.ny, s.nz}, {0.5, 0.5, 0.5}}, s); }
Lattice u_lattice(const GridSpec& s) { return with_period({{s.nx + 1, s.ny, s.nz}, {0.0, 0.5, 0.5}}, s); }
Lattice v_lattice(const GridSpec& s) { return with_period({{s.nx, s.ny + 1, s.nz}, {0.5, 0.0, 0.5}}, s); }
Lattice w_lattice(const GridSpec& s) { return with_period({{s.nx, s.ny, s.nz + 1}, {0.5, 0.5, 0.0}}, s); }

namespace {

// A position in cell units: sh[a] + p[a] along each axis. On an axis that does
// not wrap sh = 0 and p is absolute (clamped); on a periodic axis sh is the
// integer index of the lattice node a trace started from and p the offset from
// it, so traces from nodes k cells apart see the same numbers (translation
// invariance to the bit) and only the wrapped indices differ.
struct Pos {
    double p[3];
    int sh[3];
};

// Index (sh + floor(x)) mod period and the fraction x - floor(x).
inline void wrap_axis(double x, int sh, int period, long long& i, double& f) {
    const double fl = std::floor(x);
    f = x - fl;
    i = (static_cast<long long>(sh) + static_cast<long long>(fl)) % period;
    if (i < 0) i += period;
}

// The trilinear cell around p: base index, per-axis strides to the upper
// neighbour (0 on a single-sample axis or at the clamped upper edge) and the
// fractional weights. Positions are clamped into the lattice.
// Along a periodic axis the upper neighbour of the last sample is the first
// one (a negative step).
struct Corners {
    size_t base;
    std::ptrdiff_t step[3];
    double f[3];
};

inline Corners corners(const Lattice& l, const Pos& pos) {
    Corners c;
    const std::ptrdiff_t stride[3] = {1, std::ptrdiff_t(l.n[0]), std::ptrdiff_t(l.n[0]) * std::ptrdiff_t(l.n[1])};
    c.base = 0;
    const double* p = pos.p;
    for (int a = 0; a < 3; ++a) {
        const int n = l.n[a];
        if (n <= 1) {
            c.f[a] = 0;
            c.step[a] = 0;
            continue;
        }
        if (l.period[a] > 0) {
            long long i;
            wrap_axis(p[a] - l.offset[a], pos.sh[a], l.period[a], i, c.f[a]);
            c.base += size_t(i) * size_t(stride[a]);
            c.step[a] = i + 1 < n ? stride[a] : -std::ptrdiff_t(i) * stride[a];
            continue;
        }
        double x = p[a] - l.offset[a];
        x = x < 0 ? 0 : x;
        if (x >= n - 1) { // clamped at the upper edge: the last sample alone (no zero-weight neighbour)
            c.f[a] = 0;
            c.step[a] = 0;
            c.base += size_t(n - 1) * size_t(stride[a]);
            continue;
        }
        const int i = int(x);
        c.f[a] = x - i;
        c.step[a] = stride[a];
        c.base += size_t(i) * size_t(stride[a]);
    }
    return c;
}

inline double lerp_at(const float* q, const Corners& c) {
    const float* b = q + c.base;
    const std::ptrdiff_t sx = c.step[0], sy = c.step[1], sz = c.step[2];
    const double fx = c.f[0], fy = c.f[1], fz = c.f[2];
    auto row = [&](const float* r) { return double(r[0]) + fx * (double(r[sx]) - double(r[0])); };
    const double c00 = row(b), c10 = row(b + sy), c01 = row(b + sz), c11 = row(b + sy + sz);
    const double c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

inline void minmax_at(const float* q, const Corners& c, float& lo, float& hi) {
    const float* b = q + c.base;
    const std::ptrdiff_t o[8] = {0,
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

// Tricubic Catmull-Rom read of q at p (edge indices clamped, wrapped along a
// periodic axis), limited to the min/max of the 8 trilinear corners. Axes with
// one sample are skipped.
float cubic_limited_at(const Lattice& l, const float* q, const Pos& pos) {
    int idx[3][4];
    double w[3][4];
    int cnt[3];
    const double* p = pos.p;
    for (int a = 0; a < 3; ++a) {
        const int n = l.n[a];
        if (n <= 1) {
            cnt[a] = 1, idx[a][0] = 0, w[a][0] = 1;
            continue;
        }
        if (l.period[a] > 0) {
            const int P = l.period[a];
            long long i;
            double t;
            wrap_axis(p[a] - l.offset[a], pos.sh[a], P, i, t);
            catmull_rom(t, w[a]);
            cnt[a] = 4;
            for (int m = 0; m < 4; ++m) idx[a][m] = int((i - 1 + m + P) % P);
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
    minmax_at(q, corners(l, pos), lo, hi);
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
    std::ptrdiff_t up; // index step to the upper neighbour: 1, 0 (none), or back to 0 across a wrap
};
inline AxisPos axis_pos(double x, int n) { // n samples at x = 0 .. n-1
    if (n <= 1) return {0, 0.0, 0};
    x = x < 0 ? 0 : (x > n - 1 ? n - 1 : x);
    int i = int(x);
    if (i > n - 2) i = n - 2;
    return {size_t(i), x - i, 1};
}
// The same along a periodic axis of `period` cells, n samples (period or period + 1).
inline AxisPos axis_wrap(double x, int sh, int period, int n) {
    long long i;
    double f;
    wrap_axis(x, sh, period, i, f);
    return {size_t(i), f, i + 1 < n ? std::ptrdiff_t(1) : -std::ptrdiff_t(i)};
}
inline double lerp3(const float* q, const AxisPos& ax, const AxisPos& ay, const AxisPos& az, size_t sy, size_t sz) {
    Corners c;
    c.base = ax.i + ay.i * sy + az.i * sz;
    c.step[0] = ax.up;
    c.step[1] = ay.up * std::ptrdiff_t(sy);
    c.step[2] = az.up * std::ptrdiff_t(sz);
    c.f[0] = ax.f, c.f[1] = ay.f, c.f[2] = az.f;
    return lerp_at(q, c);
}
inline void velocity_fast(const MacVelocity& vel, const Pos& pos, double out[3]) {
    const GridSpec& g = vel.spec;
    const int nx = g.nx, ny = g.ny, nz = g.nz;
    const double* p = pos.p;
    const bool wx = g.periodic(0), wy = g.periodic(1);
    const AxisPos fx = wx ? axis_wrap(p[0], pos.sh[0], nx, nx + 1) : axis_pos(p[0], nx + 1),
                  cx = wx ? axis_wrap(p[0] - 0.5, pos.sh[0], nx, nx) : axis_pos(p[0] - 0.5, nx);
    const AxisPos fy = wy ? axis_wrap(p[1], pos.sh[1], ny, ny + 1) : axis_pos(p[1], ny + 1),
                  cy = wy ? axis_wrap(p[1] - 0.5, pos.sh[1], ny, ny) : axis_pos(p[1] - 0.5, ny);
    const AxisPos fz = axis_pos(p[2], nz + 1), cz = axis_pos(p[2] - 0.5, nz);
    const double inv = 1.0 / g.dx;
    out[0] = nx > 1 ? lerp3(vel.u.data(), fx, cy, cz, size_t(nx + 1), size_t(nx + 1) * ny) * inv : 0.0;
    out[1] = ny > 1 ? lerp3(vel.v.data(), cx, fy, cz, size_t(nx), size_t(nx) * (ny + 1)) * inv : 0.0;
    out[2] = nz > 1 ? lerp3(vel.w.data(), cx, cy, fz, size_t(nx), size_t(nx) * ny) * inv : 0.0;
}

// Midpoint back-trace over dt from p whose velocity v0 is already known
// (clamped into the domain, free along a periodic axis).
void trace_from(const MacVelocity& vel, const Pos& p, const double v0[3], double dt, Pos& out) {
    const GridSpec& g = vel.spec;
    const double n[3] = {double(g.nx), double(g.ny), double(g.nz)};
    const bool wrap[3] = {g.periodic(0), g.periodic(1), false};
    Pos mid;
    double v1[3];
    for (int a = 0; a < 3; ++a) {
        mid.sh[a] = out.sh[a] = p.sh[a];
        mid.p[a] = wrap[a] ? p.p[a] - 0.5 * dt * v0[a] : std::clamp(p.p[a] - 0.5 * dt * v0[a], 0.0, n[a]);
    }
    velocity_fast(vel, mid, v1);
    for (int a = 0; a < 3; ++a) out.p[a] = wrap[a] ? p.p[a] - dt * v1[a] : std::clamp(p.p[a] - dt * v1[a], 0.0, n[a]);
}

// Calls f(id, pos) for every lattice node; pos is node-relative along periodic axes.
template <class F>
void for_lattice(const Lattice& l, F&& f) {
    parallel_for_index(l.n[2], [&](int k) {
        for (int j = 0; j < l.n[1]; ++j)
            for (int i = 0; i < l.n[0]; ++i) {
                const int idx[3] = {i, j, k};
                Pos p;
                for (int a = 0; a < 3; ++a) {
                    const bool wrap = l.period[a] > 0;
                    p.sh[a] = wrap ? idx[a] : 0;
                    p.p[a] = wrap ? l.offset[a] : idx[a] + l.offset[a];
                }
                f((size_t(k) * l.n[1] + j) * l.n[0] + i, p);
            }
    });
}

Pos absolute(const double p[3]) { return {{p[0], p[1], p[2]}, {0, 0, 0}}; }


} // namespace

float sample_lattice(const Lattice& l, std::span<const float> q, const double p[3]) {
    return float(lerp_at(q.data(), corners(l, absolute(p))));
}

void velocity_at(const MacVelocity& vel, const double p[3], double out[3]) { velocity_fast(vel, absolute(p), out); }

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
    for_lattice(l, [&](size_t id, const Pos& p) {
        Pos src, dst;
        double v0[3];
        velocity_fast(vel, p, v0); // shared by the forward and backward traces
        trace_from(vel, p, v0, dt, src);
        for (int a = 0; a < 3; ++a) fwd_pos[id * 3 + size_t(a)] = float(src.p[a] - p.p[a]);
        if (!mac) return;
        trace_from(vel, p, v0, -dt, dst);
        for (int a = 0; a < 3; ++a) back_pos[id * 3 + size_t(a)] = float(dst.p[a] - p.p[a]);
    });
    auto pos = [&](const std::vector<float>& d, size_t id, const Pos& p, Pos& out) {
        for (int a = 0; a < 3; ++a) out.p[a] = p.p[a] + double(d[id * 3 + size_t(a)]), out.sh[a] = p.sh[a];
    };
    std::vector<float>& fwd_val = scratch.value;
    if (mac) fwd_val.resize(l.size());
    for (size_t f = 0; f < qs.size(); ++f) {
        std::span<const float> q = qs[f];
        std::span<float> out = outs[f];
        if (!mac) {
            for_lattice(l, [&](size_t id, const Pos& p) {
                Pos src;
                pos(fwd_pos, id, p, src);
                out[id] = cubic ? cubic_limited_at(l, q.data(), src) : float(lerp_at(q.data(), corners(l, src)));
            });
            continue;
        }
        for_lattice(l, [&](size_t id, const Pos& p) {
            Pos src;
            pos(fwd_pos, id, p, src);
            fwd_val[id] = float(lerp_at(q.data(), corners(l, src)));
        });
        // Backward step of the forward result, error correction and limiter in
        // one pass (reads fwd_val everywhere, writes only out[id]).
        for_lattice(l, [&](size_t id, const Pos& p) {
            Pos src;
            pos(fwd_pos, id, p, src);
            const float fv = fwd_val[id];
            if (near_open_edge(vel.spec, src.p)) { // never true along a periodic axis
                out[id] = fv; // keep semi-Lagrangian
                return;
            }
            Pos bsrc;
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
