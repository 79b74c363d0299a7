#include "diffusion.h"
#include "render_common.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace atlas::render::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;
// A neighbour index beyond the grid's edge (for_faces).
inline constexpr size_t kNoVoxel = ~size_t(0);

// The least sigma_t of a voxel that takes part: kDiffusionMinTau over its smallest edge.
inline double medium_min_sigma(const Vec3d& h) { return kDiffusionMinTau / std::min({h[0], h[1], h[2]}); }

struct Level {
    Level(const Vec3i& n_, const Vec3d& h_) : n(n_), h(h_), min_sig(medium_min_sigma(h_)) {}
    Vec3i n;
    Vec3d h;
    double min_sig; // a voxel takes part at sigma_t >= this (kDiffusionMinTau over its smallest edge)
    std::vector<float> sig; // sigma_t per metre
    std::vector<float> q;   // source per metre (per E)
    std::vector<float> phi;
    std::vector<float> leak; // the Marshak faces' area factor (staircase correction)
    std::vector<float> tb;   // the sun's transmittance averaged over the voxel (the source's q / sigma)
    // Thick voxels (fine level only; else empty): per axis, half the sun's
    // optical depth change across the voxel, signed by the side of its
    // sunward face (0: none), where the source lies (DiffusionGrid's
    // constructor, ForwardFlux::marshak). 3 per voxel.
    std::vector<float> near;
    // Sub-voxel surfaces (fine level only; else empty): per face (6 per voxel,
    // 2 a + (side > 0)), the distance from the node to the medium's surface
    // across that face in 1/kSurfaceUnits of a voxel on its axis
    // (shadowed_face_surfaces), and per voxel the sweep's sum over its
    // Marshak faces of leak / (h (r + 2)) (one stream the sweep reads in
    // order, where the per-face shares are scattered).
    std::vector<uint8_t> surface;
    std::vector<float> marshak_den;
    size_t idx(int x, int y, int z) const { return (size_t(z) * size_t(n[1]) + size_t(y)) * size_t(n[0]) + size_t(x); }
    size_t size() const { return size_t(n[0]) * size_t(n[1]) * size_t(n[2]); }
    double hmin() const { return std::min({h[0], h[1], h[2]}); }
    // Voxel j is medium (kNoVoxel: beyond the grid, not medium).
    bool medium(size_t j) const { return j != kNoVoxel && sig[j] >= min_sig; }
};

// Successive over-relaxation factor of the red-black sweeps.
constexpr double kOmega = 1.8;
// The Marshak boundary's resistance: phi = 0 at 2D beyond the face.
constexpr double kMarshak = 2.0;

// The node-to-surface share of voxel i's Marshak face (a, side): 0.5 (the
// face) unless the level has sub-voxel surfaces.
inline double surface_share(const Level& L, size_t i, int a, int side) {
    return L.surface.empty() ? 0.5 : L.surface[6 * i + size_t(2 * a + (side > 0 ? 1 : 0))] / double(kSurfaceUnits);
}
// That face's resistance r = 3 sigma' d, d the node's distance to the
// surface (1.5 sigma' h at the face itself).
inline double face_r(const Level& L, size_t i, int a, int side, double reduce) {
    if (L.surface.empty()) return 1.5 * reduce * L.sig[i] * L.h[a];
    return 3 * reduce * L.sig[i] * L.h[a] * surface_share(L, i, a, side);
}

// Every voxel of the level (medium or not: f decides), z slabs in parallel:
// f(i, c) with c its (x, y, z). Each call may write voxel i's own entries only.
template <class F>
void for_voxels(const Level& L, F&& f) {
    parallel_for_index(L.n[2], [&](int z) {
        for (int y = 0; y < L.n[1]; ++y)
            for (int x = 0; x < L.n[0]; ++x) {
                const int c[3] = {x, y, z};
                f(L.idx(x, y, z), c);
            }
    });
}

// Voxel c's six faces: f(a, side, j) with j the neighbour across the face on
// axis a, side -1 / +1, or kNoVoxel beyond the grid's edge.
template <class F>
void for_faces(const Level& L, const int c[3], F&& f) {
    for (int a = 0; a < 3; ++a)
        for (int side = -1; side <= 1; side += 2) {
            int cc[3] = {c[0], c[1], c[2]};
            cc[a] += side;
            f(a, side, cc[a] >= 0 && cc[a] < L.n[a] ? L.idx(cc[0], cc[1], cc[2]) : kNoVoxel);
        }
}

// coth x - 1 / x (x >= 0), by its series near 0.
double langevin(double x) {
    if (x < 1e-3) return x / 3;
    if (x > 30) return 1 - 1 / x;
    return 1 / std::tanh(x) - 1 / x;
}

// The share of the rise from the surface value to the node's phi that the
// lookups put at the face itself, for a source near the face: the profile
// really rises over the source's depth, h / (2 x), not linearly to the node
// (optical depth `half` = sigma h / 2 in). A view ray going straight in
// sees phi_s + (phi - phi_s) / (1 + sigma l) under the exponential rise of
// scale l (the node's phi beyond it); the lookups, linear from the value
// v0 at the face to phi at the node and phi beyond, see v0 (I1 - I2) + phi
// (I2 + e^-half), I1 = 1 - e^-half, I2 = (1 - e^-half (1 + half)) / half.
// Equal for v0 = phi_s + share (phi - phi_s); clamped to [0, 1].
double near_face_rise(double half, double x) {
    if (!(half > 1e-6) || !(x > 0)) return 0;
    const double e = std::exp(-half), i1 = 1 - e, i2 = (1 - e * (1 + half)) / half;
    const double want = 1 / (1 + half / x);
    return std::clamp((want - i2 - e) / (i1 - i2), 0.0, 1.0);
}

// The forward peak of the first-scattered light (P1 with an anisotropic
// source): F = -D grad phi + 3 D Q1 with Q1 = g sigma Tbar (-sun), so a face
// of normal n carries the extra flux ag Tbar (-sun . n), ag = g / (1 - g)
// (sigma cancels). ag = 0: the isotropic source.
// near: also the thick voxels' near-face source (Level::near) at Marshak
// faces; both do not depend on phi, so the balance takes them as a source
// (add_forward_source).
struct ForwardFlux {
    double ag = 0;
    Vec3d sun{{0, 0, 1}};
    bool near = false;
    // Outward through voxel i's face on axis a, side +-1, at transmittance t.
    double out(double t, int a, int side) const { return ag * t * -sun[a] * side; }
    // Outward through voxel i's Marshak face (a, side): the forward peak
    // plus the near-face source where that face is the sunward one.
    double marshak(const Level& L, size_t i, int a, int side) const {
        const double x = near_x(L, i, a, side);
        return out(L.tb[i], a, side) + (x > 0 ? near_weight(L, i, a) * L.tb[i] * L.sig[i] * L.h[a] * langevin(x) : 0.0);
    }
    // Half the sun's optical depth change across voxel i on axis a where
    // (a, side) is its sunward face and the near-face source is on; else 0.
    double near_x(const Level& L, size_t i, int a, int side) const {
        if (!near || L.near.empty()) return 0;
        const double x = L.near[3 * i + size_t(a)];
        return x * side > 0 ? std::fabs(x) : 0.0;
    }
    // The near-face treatment fades in from half a voxel's optical thickness
    // of 1 on the axis to 2: thinner voxels keep the centre source their
    // lookups were calibrated with (the 2.5D deck at 0.66: 1.06 / 1.00 /
    // 0.98 of Chandrasekhar with the sun 25 / 60 / 80 degrees high; with the
    // near-face source 0.90 / 0.94 / 0.93).
    static double near_weight(const Level& L, size_t i, int a) { return std::clamp(0.5 * L.sig[i] * L.h[a] - 1, 0.0, 1.0); }
};

// Light arriving from outside through the medium's faces (Marshak with an
// incoming partial current J: phi_s / 4 - F / 2 = J): the sky field's
// source. j[a][side > 0] is J through a face of outward normal side x axis a,
// for the sky basis L(w) = saturate(w . up), up = +z: J = int over the
// hemisphere the face sees of L (w . n) dw = 2 pi / 3 on top faces, 2 / 3 on
// side faces, 0 on bottom faces (below the horizon the sky is the horizon
// colour, which this basis leaves out). All zero for the sun's field.
// free_phi, free_flux: the field in free space, held by outside voxels away
// from the medium (the sky basis's phi = int L dw = pi and flux = int L
// (-w) dw = (0, 0, -2 pi / 3): light that has not met the cloud; 0 for the
// sun's field of scattered light).
struct Incoming {
    double j[3][2] = {{0, 0}, {0, 0}, {0, 0}};
    double free_phi = 0, free_flux_z = 0;
    double at(int a, int side) const { return j[a][side > 0 ? 1 : 0]; }
    // The incoming radiance from direction w (toward where it comes from):
    // the sky basis saturate(w . up); 0 for the sun's field.
    double radiance(const Vec3d& w) const { return free_phi > 0 ? std::max(0.0, w[2]) : 0.0; }
    // Only the sky basis: a smooth surface of outward normal n drawn in
    // voxel faces has |n_a| of its area on axis a's faces (leak_factors), so
    // its faces take in sum_a |n_a| J(a, sign n_a) / |n|_1 per unit area,
    // where the surface itself takes in E(n) = int L (w . n)+ dw =
    // (2 / 3) ((pi - t) cos t + sin t), t the angle between n and up: 15-20%
    // more on slopes 15-60 degrees from flat (a box's face keeps 1).
    // The factor E(n) / that, 1 without a gradient (or a sky: no J); n from
    // smoothed_extinction_gradient (on binary voxels the central difference
    // is an axis on every tread and riser, factor 1: the voxel-mode slab at
    // 45 degrees stayed 17% under Chandrasekhar).
    double slope_factor(const Vec3d& n) const {
        const double l1 = std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]);
        if (!(l1 > 0)) return 1;
        double stair = 0;
        for (int a = 0; a < 3; ++a) stair += std::fabs(n[a]) * at(a, n[a] > 0 ? 1 : -1);
        stair /= l1;
        const double l2 = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const double t = std::acos(std::clamp(n[2] / l2, -1.0, 1.0));
        const double e = (2.0 / 3.0) * ((kPi - t) * std::cos(t) + std::sin(t));
        return stair > 0 ? std::max(0.0, e) / stair : 1.0;
    }
    static Incoming sky_basis() {
        Incoming in;
        in.j[0][0] = in.j[0][1] = in.j[1][0] = in.j[1][1] = 2.0 / 3.0;
        in.j[2][1] = 2 * kPi / 3;
        in.free_phi = kPi;
        in.free_flux_z = -2 * kPi / 3;
        return in;
    }
};

// Outward flux through a Marshak face of a voxel of resistance r = 1.5 sigma'
// h: phi = 0 at 2D beyond the face (or phi_s / 4 - F / 2 = J with light
// coming in), F = D (phi - phi_s) / (h / 2) + G give F = (phi - 4 J + r G) / (r + 2).
inline double marshak_flux(double phi, double r, double g_out, double j_in = 0) { return (phi - 4 * j_in + r * g_out) / (r + kMarshak); }
// The surface value phi_s = 2 F + 4 J of that face.
inline double marshak_surface(double phi, double r, double g_out, double j_in) { return 2 * marshak_flux(phi, r, g_out, j_in) + 4 * j_in; }

// One colour's sweep: every voxel with (x + y + z) % 2 == colour reads only
// voxels of the other colour, so z slabs run in parallel with the same bytes.
template <bool Subvoxel>
void sweep_level(Level& L, double reduce, int colour) {
    const double min_sig = L.min_sig;
    parallel_for_index(L.n[2], [&](int z) {
        for (int y = 0; y < L.n[1]; ++y) {
            for (int x = (y + z + colour) & 1; x < L.n[0]; x += 2) {
                const size_t i = L.idx(x, y, z);
                const double si = L.sig[i];
                if (si < min_sig) continue;
                double num = L.q[i], den = 0;
                const int c[3] = {x, y, z};
                for (int a = 0; a < 3; ++a) {
                    const double ri = 1.5 * reduce * si * L.h[a];
                    const double inv_h = 1.0 / L.h[a];
                    for (int side = -1; side <= 1; side += 2) {
                        int cc[3] = {c[0], c[1], c[2]};
                        cc[a] += side;
                        if (cc[a] >= 0 && cc[a] < L.n[a]) {
                            const size_t j = L.idx(cc[0], cc[1], cc[2]);
                            const double sj = L.sig[j];
                            if (sj >= min_sig) {
                                const double k = inv_h / (ri + 1.5 * reduce * sj * L.h[a]);
                                num += k * L.phi[j];
                                den += k;
                                continue;
                            }
                        }
                        if constexpr (!Subvoxel) den += L.leak[i] * inv_h / (ri + kMarshak); // else marshak_den below
                    }
                }
                if constexpr (Subvoxel) den += L.marshak_den[i];
                const double old = L.phi[i];
                L.phi[i] = static_cast<float>(std::max(0.0, old + kOmega * (num / den - old)));
            }
        }
    });
}
// Sub-voxel surfaces or not: two loops (one loop testing for the shares and
// reading them per face cost the superstorm's solve a quarter of its time,
// with or without shares).
void sweep(Level& L, double reduce, int colour) {
    if (L.surface.empty()) sweep_level<false>(L, reduce, colour);
    else sweep_level<true>(L, reduce, colour);
}

// sigma_t at voxel (x, y, z), 0 beyond the grid.
double sigma_or_zero(const Level& L, int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= L.n[0] || y >= L.n[1] || z >= L.n[2]) return 0.0;
    return double(L.sig[L.idx(x, y, z)]);
}

// The extinction's gradient at voxel c, per metre per metre (central
// differences, 0 beyond the grid): the surface's inward normal direction.
Vec3d extinction_gradient(const Level& L, const int c[3]) {
    auto sig = [&](int x, int y, int z) { return sigma_or_zero(L, x, y, z); };
    const int x = c[0], y = c[1], z = c[2];
    return Vec3d{{(sig(x + 1, y, z) - sig(x - 1, y, z)) / L.h[0], (sig(x, y + 1, z) - sig(x, y - 1, z)) / L.h[1],
                  (sig(x, y, z + 1) - sig(x, y, z - 1)) / L.h[2]}};
}

// The extinction's gradient over the voxel's 3x3x3 neighbourhood (every
// neighbour's sigma x its offset, per metre, 0 beyond the grid): on a
// staircase of binary voxels the central difference is an axis on every
// tread and riser; this sees the slope.
Vec3d smoothed_extinction_gradient(const Level& L, const int c[3]) {
    double g[3] = {0, 0, 0};
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const double sg = sigma_or_zero(L, c[0] + dx, c[1] + dy, c[2] + dz);
                g[0] += sg * dx;
                g[1] += sg * dy;
                g[2] += sg * dz;
            }
    return Vec3d{{g[0] / L.h[0], g[1] / L.h[1], g[2] / L.h[2]}};
}

// Incoming::slope_factor at voxel c; 1 without light coming in (the sun's
// field), where the 27-voxel gradient is not needed.
double slope_factor_at(const Level& L, const int c[3], const Incoming& in) {
    return in.free_phi == 0 ? 1.0 : in.slope_factor(smoothed_extinction_gradient(L, c) * -1.0);
}

// Outside-medium voxels next to the medium take the mean of their medium
// neighbours' Marshak surface values 2 phi / (r + 2), so that lookups just
// outside the medium see the surface, not 0 (measured on the calibration
// shapes: the same as extrapolating through the surface value, 0.069 against
// 0.070 mean error). Reads medium voxels only.
void fill_outside(Level& L, double reduce, bool extrapolate, const ForwardFlux& ff, const Incoming& in) {
    for_voxels(L, [&](size_t i, const int c[3]) {
        if (L.medium(i)) return;
        double acc = 0;
        int cnt = 0;
        for_faces(L, c, [&](int a, int side, size_t j) {
            if (!L.medium(j)) return;
            const double rj = face_r(L, j, a, -side, reduce);
            double surface = marshak_surface(L.phi[j], rj, ff.marshak(L, j, a, -side), in.at(a, -side));
            const double x = ff.near_x(L, j, a, -side);
            if (extrapolate && x > 0) surface += ForwardFlux::near_weight(L, j, a) * near_face_rise(0.5 * L.sig[j] * L.h[a], x) * (L.phi[j] - surface);
            if (!extrapolate) acc += surface;
            else if (L.surface.empty()) acc += 2 * surface - L.phi[j];
            else acc += L.phi[j] + (surface - L.phi[j]) / surface_share(L, j, a, -side); // linear through the surface
            ++cnt;
        });
        L.phi[i] = static_cast<float>(cnt ? acc / cnt : in.free_phi); // may be < 0 extrapolated: lookups clamp
    });
}

// A smooth surface of unit normal n drawn in voxel faces has |nx| + |ny| +
// |nz| times its area on the axis faces (1.5x on average over a sphere), so
// the Marshak leak through a boundary voxel's faces is scaled by 1 / that
// sum, n from the density gradient (central differences, 0 beyond the grid).
// Axis-aligned faces (a box) keep factor 1; so does a voxel with no gradient.
void leak_factors(Level& L) {
    L.leak.assign(L.size(), 1.0f);
    for_voxels(L, [&](size_t i, const int c[3]) {
        const Vec3d g = extinction_gradient(L, c);
        const double l2 = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), l1 = std::fabs(g[0]) + std::fabs(g[1]) + std::fabs(g[2]);
        if (l1 > 0) L.leak[i] = static_cast<float>(l2 / l1);
    });
}

Level coarsen(const Level& f, const Vec3d& size) {
    Vec3i n;
    Vec3d h;
    for (int a = 0; a < 3; ++a) {
        n[a] = std::max(1, (f.n[a] + 1) / 2);
        h[a] = size[a] / n[a];
    }
    Level c(n, h);
    c.sig.assign(c.size(), 0.0f);
    c.q.assign(c.size(), 0.0f);
    c.tb.assign(c.size(), 0.0f);
    c.phi.assign(c.size(), 0.0f);
    parallel_for_index(c.n[2], [&](int z) {
        for (int y = 0; y < c.n[1]; ++y)
            for (int x = 0; x < c.n[0]; ++x) {
                double s = 0, q = 0, t = 0;
                int cnt = 0;
                for (int dz = 0; dz < 2; ++dz)
                    for (int dy = 0; dy < 2; ++dy)
                        for (int dx = 0; dx < 2; ++dx) {
                            const int fx = 2 * x + dx, fy = 2 * y + dy, fz = 2 * z + dz;
                            if (fx >= f.n[0] || fy >= f.n[1] || fz >= f.n[2]) continue;
                            const size_t j = f.idx(fx, fy, fz);
                            s += f.sig[j];
                            q += f.q[j];
                            t += f.tb[j];
                            ++cnt;
                        }
                const size_t i = c.idx(x, y, z);
                c.sig[i] = static_cast<float>(s / cnt);
                c.q[i] = static_cast<float>(q / cnt);
                c.tb[i] = static_cast<float>(t / cnt);
            }
    });
    leak_factors(c);
    return c;
}

void prolong(const Level& c, Level& f) {
    parallel_for_index(f.n[2], [&](int z) {
        for (int y = 0; y < f.n[1]; ++y)
            for (int x = 0; x < f.n[0]; ++x)
                f.phi[f.idx(x, y, z)] = c.phi[c.idx(std::min(x / 2, c.n[0] - 1), std::min(y / 2, c.n[1] - 1), std::min(z / 2, c.n[2] - 1))];
    });
}

void solve(Level& L, double reduce, int sweeps, bool extrapolate, const ForwardFlux& ff, const Incoming& in) {
    for (int s = 0; s < sweeps; ++s) {
        sweep(L, reduce, 0);
        sweep(L, reduce, 1);
    }
    fill_outside(L, reduce, extrapolate, ff, in);
}

// The incoming light's share of the balance (independent of phi, so it is a
// source): each Marshak face adds leak x 4 J / ((r + 2) h). Replaces q.
void set_incoming_source(Level& L, double reduce, const Incoming& in) {
    L.q.assign(L.size(), 0.0f);
    for_voxels(L, [&](size_t i, const int c[3]) {
        if (!L.medium(i)) return;
        double q = 0;
        for_faces(L, c, [&](int a, int side, size_t j) {
            if (L.medium(j)) return;
            const double r = face_r(L, i, a, side, reduce);
            q += L.leak[i] * 4 * in.at(a, side) / ((r + kMarshak) * L.h[a]);
        });
        if (q > 0) q *= slope_factor_at(L, c, in); // only voxels with sky coming in
        L.q[i] = static_cast<float>(q);
    });
}

// The forward flux's divergence moved into the source (it does not depend
// on phi): interior faces with the two voxels' mean Tbar, Marshak faces
// through marshak_flux's r G / (r + 2). Writes each voxel's own q only.
void add_forward_source(Level& L, double reduce, const ForwardFlux& ff) {
    std::vector<float> q = L.q;
    for_voxels(L, [&](size_t i, const int c[3]) {
        if (!L.medium(i)) return;
        double out = 0;
        for_faces(L, c, [&](int a, int side, size_t j) {
            if (L.medium(j)) {
                out += ff.out(0.5 * (L.tb[i] + L.tb[j]), a, side) / L.h[a];
            } else {
                const double r = face_r(L, i, a, side, reduce);
                out += L.leak[i] * r * ff.marshak(L, i, a, side) / (r + kMarshak) / L.h[a];
            }
        });
        q[i] = static_cast<float>(L.q[i] - out);
    });
    L.q = std::move(q);
}

// Cascade: the coarsest level solved with 4x the sweeps, each finer one
// started from the coarser solution.
void cascade(std::vector<Level>& levels, double reduce, int sweeps, bool thick, const ForwardFlux& ff, const Incoming& in) {
    for (size_t l = levels.size(); l-- > 0;) {
        if (l + 1 < levels.size()) prolong(levels[l + 1], levels[l]);
        solve(levels[l], reduce, l + 1 == levels.size() ? 4 * sweeps : sweeps, thick, ff, in);
    }
}

// The diffuse flux F = -D grad phi (+ the forward flux) per voxel (per E):
// the mean of the face fluxes on each axis (marshak_flux outward at the
// medium's faces); outside voxels next to the medium take their medium
// neighbours' mean, others 0.
std::vector<float> voxel_fluxes(const Level& top, double reduce, const ForwardFlux& ff, const Incoming& in) {
    const std::vector<float>& phi = top.phi;
    std::vector<float> flux(3 * top.size(), 0.0f);
    for_voxels(top, [&](size_t i, const int c[3]) {
        if (!top.medium(i)) return;
        const double si = top.sig[i];
        double f[3] = {0, 0, 0};
        for_faces(top, c, [&](int a, int side, size_t j) {
            const double ri = 1.5 * reduce * si * top.h[a];
            double face; // flux toward +axis through this face
            if (top.medium(j))
                face = side * ((phi[i] - phi[j]) / (ri + 1.5 * reduce * top.sig[j] * top.h[a]) + ff.out(0.5 * (top.tb[i] + top.tb[j]), a, side));
            else
                face = side * marshak_flux(phi[i], face_r(top, i, a, side, reduce), ff.marshak(top, i, a, side), in.at(a, side));
            f[a] += 0.5 * face;
        });
        for (int a = 0; a < 3; ++a) flux[3 * i + size_t(a)] = static_cast<float>(f[a]);
    });
    for_voxels(top, [&](size_t i, const int c[3]) {
        if (top.medium(i)) return;
        double acc[3] = {0, 0, 0};
        int cnt = 0;
        for_faces(top, c, [&](int, int, size_t j) {
            if (!top.medium(j)) return;
            // flux of medium voxels is final here: this pass writes outside voxels only
            for (int b = 0; b < 3; ++b) acc[b] += flux[3 * j + size_t(b)];
            ++cnt;
        });
        if (cnt)
            for (int b = 0; b < 3; ++b) flux[3 * i + size_t(b)] = static_cast<float>(acc[b] / cnt);
        else
            flux[3 * i + 2] = static_cast<float>(in.free_flux_z);
    });
    return flux;
}

// The light the medium sheds onto other parts of itself (inter-cloud light):
// the Marshak boundary lets light that leaves the medium go for good, but in
// a field of clouds it lights the neighbours. Per boundary voxel, kShedRays^2
// cosine-weighted rays about its outward normal (minus the density gradient:
// rays about the axis faces would graze the voxel staircase of the same
// surface), starting kShedStart voxels out along it (so a convex surface
// never sees itself: the 12 calibration shapes keep their errors), march
// the grid a voxel at a time, up to kShedReach voxels; a ray that meets
// medium at least kShedMinDistance voxels on brings that voxel's mean
// outgoing current (its boundary faces' net Marshak outflow plus the
// current jin that came in on the previous pass; seen as Lambertian). The
// mean over the rays is the voxel's incoming current J on its boundary
// faces (written to jin), returned as the source leak x 4 J / ((r + 2) h)
// summed over them (as set_incoming_source). One pass: one bounce between
// clouds. The shed light enters the balance only: the surface values and
// face fluxes the lookups read (fill_outside, voxel_fluxes) leave it out.
// With light coming in (the sky field): the faces' outgoing current counts
// the sky's J too, and a ray that meets medium also takes away the sky it
// hides, pi x the basis's radiance along it (set_incoming_source counted it
// in). A tower's flank sees the bright tops of the deck around it below
// the horizon, where the basis is 0; the superstorm's sky part went from
// +8% to +5% (docs/render.md, "2.5D against Cycles").
constexpr int kShedRays = 3, kShedReach = 48, kShedMinDistance = 1;
constexpr double kShedStart = 1.0; // rays start this many voxels out along the normal
// Bounces between clouds: each pass sheds the outgoing current (net outflow
// plus what came in) of the last solve. 2: hzd_weather within 0.1 point of 3.
constexpr int kShedBounces = 2;
// The sky field's: 1 (superstorm 11.40% against 11.33% with 2, at half the
// cost).
constexpr int kSkyShedBounces = 1;
std::vector<float> shed_light_source(const Level& L, double reduce, const ForwardFlux& ff, const Incoming& in, std::vector<float>& jin) {
    std::vector<float> jout(L.size(), 0.0f);
    for_voxels(L, [&](size_t i, const int c[3]) {
        if (!L.medium(i)) return;
        double acc = 0;
        int cnt = 0;
        // The outgoing partial current: the net outflow plus what came in.
        const double j_shed = jin.empty() ? 0.0 : double(jin[i]);
        double slope = -1; // computed at the first open face: interior voxels have none
        for_faces(L, c, [&](int a, int side, size_t j) {
            if (L.medium(j)) return;
            if (slope < 0) slope = slope_factor_at(L, c, in);
            const double j_in = std::max(0.0, in.at(a, side) * slope + j_shed);
            acc += std::max(0.0, marshak_flux(L.phi[i], face_r(L, i, a, side, reduce), ff.marshak(L, i, a, side), j_in) + j_in);
            ++cnt;
        });
        if (cnt) jout[i] = static_cast<float>(acc / cnt);
    });
    const double hm = L.hmin();
    constexpr double kTwoPi = 6.283185307179586;
    std::vector<float> q(L.size(), 0.0f), jn(L.size(), 0.0f);
    for_voxels(L, [&](size_t i, const int c[3]) {
        if (!L.medium(i)) return;
        double conductance = 0, faces[3] = {0, 0, 0};
        for_faces(L, c, [&](int a, int side, size_t j) {
            if (L.medium(j)) return;
            const double r = face_r(L, i, a, side, reduce);
            conductance += L.leak[i] * 4 / ((r + kMarshak) * L.h[a]);
            faces[a] += side;
        });
        if (conductance == 0) return;
        Vec3d n = extinction_gradient(L, c) * -1.0; // outward, in metres (not voxel units: the 2.5D patch's voxels are flatter than wide)
        if (!(dot(n, n) > 0)) n = Vec3d{{faces[0], faces[1], faces[2]}}; // no gradient: the open faces' mean
        if (!(dot(n, n) > 0)) return;
        n = normalized(n);
        const Vec3d t1 = normalized(std::fabs(n[0]) < 0.9 ? Vec3d{{0, n[2], -n[1]}} : Vec3d{{-n[2], 0, n[0]}});
        const Vec3d t2 = cross(n, t1);
        double sum = 0;
        for (int u = 0; u < kShedRays; ++u)
            for (int v = 0; v < kShedRays; ++v) {
                const double r = std::sqrt((u + 0.5) / kShedRays), ph = kTwoPi * (v + 0.5 + 0.5 * (u & 1)) / kShedRays;
                const Vec3d w = n * std::sqrt(std::max(0.0, 1 - r * r)) + t1 * (r * std::cos(ph)) + t2 * (r * std::sin(ph));
                double d[3], p[3];
                for (int k = 0; k < 3; ++k) {
                    d[k] = w[k] * hm / L.h[k]; // one smallest edge per step, in voxel units
                    p[k] = c[k] + 0.5 + n[k] * kShedStart * hm / L.h[k];
                }
                for (int step = 0; step < kShedReach; ++step) {
                    for (int k = 0; k < 3; ++k) p[k] += d[k];
                    const int qx = int(std::floor(p[0])), qy = int(std::floor(p[1])), qz = int(std::floor(p[2]));
                    if (qx < 0 || qy < 0 || qz < 0 || qx >= L.n[0] || qy >= L.n[1] || qz >= L.n[2]) break;
                    const size_t j = L.idx(qx, qy, qz);
                    if (j == i || !L.medium(j)) continue;
                    if (step >= kShedMinDistance) sum += jout[j] - kPi * in.radiance(w);
                    break;
                }
            }
        q[i] = static_cast<float>(conductance * sum / (kShedRays * kShedRays));
        jn[i] = static_cast<float>(sum / (kShedRays * kShedRays));
    });
    jin = std::move(jn);
    return q;
}

// The light shed onto other clouds (shed_light_source) as a further source,
// the fine level solved again from where it is after each bounce.
void shed_bounces(Level& L, double reduce, int sweeps, bool thick, const ForwardFlux& ff, const Incoming& in, int bounces) {
    const std::vector<float> q0 = L.q;
    std::vector<float> jin;
    for (int b = 0; b < bounces; ++b) {
        const std::vector<float> shed = shed_light_source(L, reduce, ff, in, jin);
        // The sky's shed can be negative (the sky it hides): it takes no
        // voxel below 0 (the sun's q0 may be, the forward flux's divergence).
        for (size_t i = 0; i < L.q.size(); ++i) L.q[i] = std::max(std::min(q0[i], 0.0f), q0[i] + shed[i]);
        solve(L, reduce, 2 * sweeps, thick, ff, in);
    }
}

} // namespace

std::vector<uint8_t> shadowed_face_surfaces(const LightGrid& grid, double extinction, const LightGrid::DensityFn& density) {
    const Vec3i res = grid.resolution();
    const Vec3d h = grid.voxel(), sun = grid.sun_direction();
    const Box3d& box = grid.bounds();
    const auto& dens = grid.density();
    const double min_sig = medium_min_sigma(h); // the fine Level's
    const size_t n = size_t(res[0]) * size_t(res[1]) * size_t(res[2]);
    std::vector<uint8_t> share(6 * n, uint8_t(kSurfaceUnits / 2));
    auto idx = [&](int x, int y, int z) { return (size_t(z) * size_t(res[1]) + size_t(y)) * size_t(res[0]) + size_t(x); };
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const size_t i = idx(x, y, z);
                const double node = dens[i];
                if (!(extinction * node >= min_sig)) continue;
                const int c[3] = {x, y, z};
                for (int a = 0; a < 3; ++a)
                    for (int side = -1; side <= 1; side += 2) {
                        if (!(side * sun[a] < 0)) continue; // a face turned toward the sun (or edge-on) keeps the face
                        int cc[3] = {c[0], c[1], c[2]};
                        cc[a] += side;
                        if (cc[a] >= 0 && cc[a] < res[a] && extinction * dens[idx(cc[0], cc[1], cc[2])] >= min_sig) continue; // inside the medium
                        // The density's share of the node's at t voxels from the node on this axis.
                        auto ratio = [&](double t) {
                            double p[3] = {box.min[0] + (x + 0.5) * h[0], box.min[1] + (y + 0.5) * h[1], box.min[2] + (z + 0.5) * h[2]};
                            p[a] += side * t * h[a];
                            const double r = density(p[0], p[1], p[2]) / node;
                            return r > 0 ? std::min(r, 1.0) : 0.0; // NaN: 0
                        };
                        double mass = 0;
                        int first_out = kSurfaceSamples; // the first sample under half the node's density
                        bool step = true; // every sample in (>= 0.99) up to first_out, out (<= 0.01) after
                        for (int k = 0; k < kSurfaceSamples; ++k) {
                            const double r = ratio((k + 0.5) / kSurfaceSamples);
                            mass += r;
                            if (r < 0.5 && first_out == kSurfaceSamples) first_out = k;
                            step = step && (k < first_out ? r >= 0.99 : r <= 0.01);
                        }
                        double d = mass / kSurfaceSamples;
                        if (step) {
                            // A sharp edge: the midpoint samples place it to a quarter voxel
                            // only; bisect the interval it lies in (past the last sample: up
                            // to the neighbour's centre) to 1/64 voxel.
                            double lo = first_out == 0 ? 0.0 : (first_out - 0.5) / kSurfaceSamples;
                            double hi = first_out == kSurfaceSamples ? 1.0 : (first_out + 0.5) / kSurfaceSamples;
                            for (int b = 0; b < kSurfaceBisections; ++b) {
                                const double mid = 0.5 * (lo + hi);
                                (ratio(mid) >= 0.5 ? lo : hi) = mid;
                            }
                            d = 0.5 * (lo + hi);
                        }
                        // At least half a sample: the lookups extrapolate through the surface over d.
                        d = std::clamp(d, 0.5 / kSurfaceSamples, 1.0);
                        share[6 * i + size_t(2 * a + (side > 0 ? 1 : 0))] = static_cast<uint8_t>(std::lround(d * kSurfaceUnits));
                    }
            }
    });
    return share;
}

DiffusionGrid::DiffusionGrid(const LightGrid& grid, double extinction, double g, int sweeps, Voxels voxels, bool forward, bool sky, bool inter_cloud,
                             std::vector<uint8_t> surfaces)
    : res_(grid.resolution()), bounds_(grid.bounds()), voxel_(grid.voxel()) {
    const bool thick = voxels == Voxels::Thick;
    const double reduce = 1 - g;
    const Vec3d size = bounds_.size();
    std::vector<Level> levels;
    levels.reserve(16);
    levels.emplace_back(res_, voxel_);
    Level& fine = levels[0];
    const size_t n = fine.size();
    fine.sig.resize(n);
    fine.q.resize(n);
    fine.tb.assign(n, 0.0f);
    fine.phi.assign(n, 0.0f);
    if (thick) fine.near.assign(3 * n, 0.0f);
    if (thick && surfaces.size() == 6 * n) fine.surface = std::move(surfaces);
    // The sun's mean chord through a voxel: volume / projected area.
    const Vec3d& sun = grid.sun_direction();
    const double chord = 1.0 / (std::fabs(sun[0]) / voxel_[0] + std::fabs(sun[1]) / voxel_[1] + std::fabs(sun[2]) / voxel_[2]);
    const auto& dens = grid.density();
    const auto& depth = grid.sun_depths();
    const double vol = voxel_[0] * voxel_[1] * voxel_[2];
    const double min_sig = fine.min_sig;
    const size_t stride[3] = {1, size_t(res_[0]), size_t(res_[0]) * size_t(res_[1])};
    double src = 0;
    for (size_t i = 0; i < n; ++i) {
        const double sig = extinction * dens[i];
        fine.sig[i] = static_cast<float>(sig);
        const double tau = extinction * depth[i];
        double q = sig * std::exp(-tau);
        if (thick) {
            // The mean of T over the voxel from the optical depth's gradient:
            // T_c prod_a sinh(x_a) / x_a, x_a = |d tau / d a| h_a / 2, each
            // gradient the steeper one-sided difference (at the sunlit
            // surface the sun-side one crosses out of the medium).
            const int c[3] = {int(i % stride[1]), int((i / stride[1]) % size_t(res_[1])), int(i / stride[2])};
            double x[3], sum = 0;
            int sunward[3];
            for (int a = 0; a < 3; ++a) {
                // lo / hi > 0: the neighbour below / above on axis a is nearer the sun
                const double lo = c[a] > 0 ? double(depth[i]) - depth[i - stride[a]] : 0.0;
                const double hi = c[a] + 1 < res_[a] ? double(depth[i]) - depth[i + stride[a]] : 0.0;
                x[a] = 0.5 * extinction * std::max(std::fabs(lo), std::fabs(hi));
                sunward[a] = hi > lo ? (hi > 0 ? 1 : 0) : (lo > 0 ? -1 : 0);
                sum += x[a];
            }
            // The voxel's most sunward corner has a depth >= 0.
            const double scale = sum > tau ? tau / sum : 1.0;
            double f = 1;
            for (int a = 0; a < 3; ++a) {
                const double xa = x[a] * scale;
                if (xa > 1e-6) f *= std::sinh(std::min(xa, 300.0)) / xa;
            }
            q = std::min(sig, q * f); // mean T <= 1
            // Where the source lies: T falls by e^(2 x_a) across the voxel
            // on axis a, so the deposit's centroid sits (h_a / 2) L(x_a)
            // toward the sunward face (L the Langevin function, coth x -
            // 1 / x: 0 in a thin voxel, -> 1 in a thick one). A source at
            // depth d under a Marshak face of resistance r = 1.5 sigma' h
            // raises the node's phi as if at the centre, less the part it
            // does not cross: F = (phi + r (1 - 2 d / h) q h) / (r + 2), so
            // that face passes q h_a L(x_a) straight out (ForwardFlux::
            // marshak). Without it a voxel 5 mean free paths thick holds its
            // source 2.5 deep: the deck was 30-35% too bright and the light
            // spread into a thick cloud's shadowed side.
            if (sig >= min_sig)
                for (int a = 0; a < 3; ++a) fine.near[3 * i + size_t(a)] = static_cast<float>(sunward[a] * x[a] * scale);
        } else {
            // The source averaged over the chord: sigma x mean of T over it,
            // T = e^-tau at the centre, e^(-tau +- x) at the chord's ends.
            const double x = 0.5 * sig * chord;
            if (x > 1e-6) q = sig * (std::exp(-std::max(0.0, tau - x)) - std::exp(-(tau + x))) / (2 * x);
        }
        fine.q[i] = sig >= min_sig ? static_cast<float>(q) : 0.0f;
        fine.tb[i] = sig >= min_sig ? static_cast<float>(q / sig) : 0.0f;
        src += fine.q[i] * vol;
    }
    source_total_ = src;
    leak_factors(fine);
    if (!fine.surface.empty()) {
        fine.marshak_den.assign(n, 0.0f);
        for_voxels(fine, [&](size_t i, const int c[3]) {
            if (!fine.medium(i)) return;
            double den = 0;
            for_faces(fine, c, [&](int a, int side, size_t j) {
                if (!fine.medium(j)) den += fine.leak[i] / (fine.h[a] * (face_r(fine, i, a, side, reduce) + kMarshak));
            });
            fine.marshak_den[i] = static_cast<float>(den);
        });
    }
    ForwardFlux ff;
    ff.near = thick;
    if (forward) {
        ff.ag = g / (1 - g);
        ff.sun = sun;
    }
    if (forward || thick) add_forward_source(fine, reduce, ff);
    while (std::max({levels.back().n[0], levels.back().n[1], levels.back().n[2]}) > 4) levels.push_back(coarsen(levels.back(), size));
    cascade(levels, reduce, sweeps, thick, ff, Incoming{});
    if (inter_cloud) shed_bounces(levels[0], reduce, sweeps, thick, ff, Incoming{}, kShedBounces);
    const Level& top = levels[0]; // (push_back above moved the levels)
    phi_ = top.phi;
    tbar_ = top.tb;
    // Outflow through the medium's boundary faces (the conservation check).
    double out = 0;
    for (int z = 0; z < res_[2]; ++z) // serial: the same sum for any thread count
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x) {
                const size_t i = top.idx(x, y, z);
                if (!top.medium(i)) continue;
                const int c[3] = {x, y, z};
                for_faces(top, c, [&](int a, int side, size_t j) {
                    if (top.medium(j)) return;
                    out += top.leak[i] * (vol / voxel_[a]) * marshak_flux(phi_[i], face_r(top, i, a, side, reduce), ff.marshak(top, i, a, side));
                });
            }
    outflow_total_ = out;
    flux_ = voxel_fluxes(top, reduce, ff, Incoming{});
    if (sky) {
        // The sky basis saturate(w . up) through the faces: no volume
        // source, no forward peak; every level gets its own faces' source.
        const Incoming in = Incoming::sky_basis();
        for (Level& L : levels) {
            set_incoming_source(L, reduce, in);
            std::fill(L.phi.begin(), L.phi.end(), 0.0f);
        }
        cascade(levels, reduce, sweeps, thick, ForwardFlux{}, in);
        if (inter_cloud) shed_bounces(levels[0], reduce, sweeps, thick, ForwardFlux{}, in, kSkyShedBounces);
        sky_phi_ = levels[0].phi;
        sky_flux_ = voxel_fluxes(levels[0], reduce, ForwardFlux{}, in);
    }
    g_ = g;
}

double DiffusionGrid::p1_weight(const std::vector<float>& phi_grid, const std::vector<float>& flux, const size_t idx[8], const double w[8],
                                 const Vec3d& toward_eye) const {
    double phi = 0, f[3] = {0, 0, 0};
    for (int k = 0; k < 8; ++k) {
        phi += w[k] * phi_grid[idx[k]];
        for (int b = 0; b < 3; ++b) f[b] += w[k] * flux[3 * idx[k] + size_t(b)];
    }
    phi = std::max(0.0, phi);
    return std::max(0.0, phi + 3 * g_ * (f[0] * toward_eye[0] + f[1] * toward_eye[1] + f[2] * toward_eye[2]));
}

void DiffusionGrid::radiances(double x, double y, double z, const Vec3d& toward_eye, double& sun, double& sky, double* mean_t) const {
    constexpr double kFourPi = 4 * 3.14159265358979323846;
    double w[8];
    size_t idx[8];
    corners(x, y, z, idx, w);
    sun = p1_weight(phi_, flux_, idx, w, toward_eye);
    sky = sky_phi_.empty() ? -1.0 : p1_weight(sky_phi_, sky_flux_, idx, w, toward_eye) / kFourPi;
    if (mean_t) *mean_t = mean_transmittance(idx, w);
}

double DiffusionGrid::mean_sun_transmittance(double x, double y, double z) const {
    double w[8];
    size_t idx[8];
    corners(x, y, z, idx, w);
    return mean_transmittance(idx, w);
}

double DiffusionGrid::mean_transmittance(const size_t idx[8], const double w[8]) const {
    double t = 0, ws = 0;
    for (int k = 0; k < 8; ++k)
        if (tbar_[idx[k]] > 0) { t += w[k] * tbar_[idx[k]]; ws += w[k]; }
    return ws > 0 ? t / ws : -1.0;
}

void DiffusionGrid::corners(double x, double y, double z, size_t idx[8], double w[8]) const {
    const double u[3] = {(x - bounds_.min[0]) / voxel_[0] - 0.5, (y - bounds_.min[1]) / voxel_[1] - 0.5, (z - bounds_.min[2]) / voxel_[2] - 0.5};
    int i0[3], i1[3];
    double t[3];
    for (int a = 0; a < 3; ++a) {
        const double v = std::clamp(u[a], 0.0, double(res_[a] - 1));
        i0[a] = std::min(static_cast<int>(v), res_[a] - 1);
        i1[a] = std::min(i0[a] + 1, res_[a] - 1);
        t[a] = v - i0[a];
    }
    const size_t row = size_t(res_[0]), slab = row * size_t(res_[1]);
    for (int k = 0; k < 8; ++k) {
        const int xx = k & 1 ? i1[0] : i0[0], yy = k & 2 ? i1[1] : i0[1], zz = k & 4 ? i1[2] : i0[2];
        idx[k] = size_t(zz) * slab + size_t(yy) * row + size_t(xx);
        w[k] = (k & 1 ? t[0] : 1 - t[0]) * (k & 2 ? t[1] : 1 - t[1]) * (k & 4 ? t[2] : 1 - t[2]);
    }
}

} // namespace atlas::render::detail
