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

struct Stencil {
    size_t idx[8];
    double wt[8];
};

// Corner indices and weights of the trilinear stencil at p.
Stencil stencil(const Lattice& l, const double p[3]) {
    int i0[3], i1[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        double x = p[a] - l.offset[a];
        double hi = double(l.n[a] - 1);
        x = std::clamp(x, 0.0, hi);
        int i = std::min(int(x), std::max(l.n[a] - 2, 0));
        f[a] = l.n[a] > 1 ? x - i : 0.0;
        i0[a] = i;
        i1[a] = std::min(i + 1, l.n[a] - 1);
    }
    Stencil s;
    int c = 0;
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx, ++c) {
                int x = dx ? i1[0] : i0[0], y = dy ? i1[1] : i0[1], z = dz ? i1[2] : i0[2];
                s.idx[c] = (size_t(z) * l.n[1] + y) * l.n[0] + x;
                s.wt[c] = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
            }
    return s;
}

// True when p lies within one cell of a domain edge along an axis with more than one cell.
bool near_edge(const GridSpec& g, const double p[3]) {
    const int n[3] = {g.nx, g.ny, g.nz};
    for (int a = 0; a < 3; ++a)
        if (n[a] > 1 && (p[a] < 1.0 || p[a] > n[a] - 1.0)) return true;
    return false;
}

void trace(const MacVelocity& vel, const double p[3], double dt, double out[3]) {
    const GridSpec& g = vel.spec;
    const double n[3] = {double(g.nx), double(g.ny), double(g.nz)};
    double v0[3], mid[3], v1[3];
    velocity_at(vel, p, v0);
    for (int a = 0; a < 3; ++a) mid[a] = std::clamp(p[a] - 0.5 * dt * v0[a], 0.0, n[a]);
    velocity_at(vel, mid, v1);
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
    Stencil s = stencil(l, p);
    double v = 0;
    for (int c = 0; c < 8; ++c) v += s.wt[c] * double(q[s.idx[c]]);
    return float(v);
}

void velocity_at(const MacVelocity& vel, const double p[3], double out[3]) {
    const GridSpec& g = vel.spec;
    double inv = 1.0 / g.dx;
    out[0] = sample_lattice(u_lattice(g), vel.u, p) * inv;
    out[1] = g.ny > 1 ? sample_lattice(v_lattice(g), vel.v, p) * inv : 0.0;
    out[2] = sample_lattice(w_lattice(g), vel.w, p) * inv;
    if (g.nx == 1) out[0] = 0;
}

void advect_many(const MacVelocity& vel, const Lattice& l, std::span<const std::span<const float>> qs,
                 std::span<const std::span<float>> outs, double dt, AdvectionScheme scheme) {
    if (qs.size() != outs.size()) throw Error("sim advect: as many outputs as inputs expected");
    for (size_t f = 0; f < qs.size(); ++f)
        if (qs[f].size() != l.size() || outs[f].size() != l.size()) throw Error("sim advect: field size does not match its lattice");
    if (!std::isfinite(dt) || dt < 0) throw Error("sim advect: dt must be finite and >= 0");
    // Trace once per lattice node and reuse it for every field (and, for
    // MacCormack, for the limiter); the backward trace likewise.
    std::vector<float> fwd_pos(l.size() * 3), back_pos;
    for_lattice(l, [&](size_t id, const double p[3]) {
        double src[3];
        trace(vel, p, dt, src);
        for (int a = 0; a < 3; ++a) fwd_pos[id * 3 + size_t(a)] = float(src[a] - p[a]);
    });
    auto pos = [&](const std::vector<float>& d, size_t id, const double p[3], double out[3]) {
        for (int a = 0; a < 3; ++a) out[a] = p[a] + double(d[id * 3 + size_t(a)]);
    };
    if (scheme == AdvectionScheme::MacCormack) {
        back_pos.resize(l.size() * 3);
        for_lattice(l, [&](size_t id, const double p[3]) {
            double src[3];
            trace(vel, p, -dt, src);
            for (int a = 0; a < 3; ++a) back_pos[id * 3 + size_t(a)] = float(src[a] - p[a]);
        });
    }
    std::vector<float> back;
    for (size_t f = 0; f < qs.size(); ++f) {
        std::span<const float> q = qs[f];
        std::span<float> out = outs[f];
        for_lattice(l, [&](size_t id, const double p[3]) {
            double src[3];
            pos(fwd_pos, id, p, src);
            out[id] = sample_lattice(l, q, src);
        });
        if (scheme == AdvectionScheme::SemiLagrangian) continue;
        back.resize(l.size());
        for_lattice(l, [&](size_t id, const double p[3]) {
            double src[3];
            pos(back_pos, id, p, src);
            back[id] = sample_lattice(l, out, src);
        });
        for_lattice(l, [&](size_t id, const double p[3]) {
            double src[3];
            pos(fwd_pos, id, p, src);
            if (near_edge(vel.spec, src)) return; // keep semi-Lagrangian
            Stencil s = stencil(l, src);
            float lo = q[s.idx[0]], hi = lo;
            for (int c = 1; c < 8; ++c) {
                lo = std::min(lo, q[s.idx[c]]);
                hi = std::max(hi, q[s.idx[c]]);
            }
            float corrected = out[id] + 0.5f * (q[id] - back[id]);
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
    const GridSpec& g = vel.spec;
    if (out.u.size() != vel.u.size() || out.v.size() != vel.v.size() || out.w.size() != vel.w.size()) out = MacVelocity(g);
    advect(vel, u_lattice(g), vel.u, out.u, dt, scheme);
    if (g.ny > 1) advect(vel, v_lattice(g), vel.v, out.v, dt, scheme);
    advect(vel, w_lattice(g), vel.w, out.w, dt, scheme);
    out.enforce_walls();
}

} // namespace atlas::sim
