// Multigrid-preconditioned CG pressure projection (see pressure.h).
#include "atlas/sim/pressure.h"

#include "atlas/core/error.h"
#include "atlas/sim/sim_options.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace atlas::sim {
namespace {

// Member `member` of ProjectionOptions against the bounds of its node option
// pressure_<member> (sim_options.h).
void check_option(double v, const std::string& member) {
    const TextOption<SimOptions>& o = sim_option("pressure_" + member);
    if (!(v >= o.min && v <= o.max)) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "sim pressure: %s expected in [%g, %g]", member.c_str(), o.min, o.max);
        throw Error(buf);
    }
}

// Sum of per-slice partial sums, added in slice order (deterministic).
template <class F>
double reduce_slices(int nz, std::vector<double>& partial, F&& f) {
    partial.assign(size_t(nz), 0.0);
    parallel_for_index(nz, [&](int k) { partial[size_t(k)] = f(k); });
    double s = 0;
    for (double p : partial) s += p;
    return s;
}

// Aggregation (piecewise-constant) coarse corrections are too small by about 2x
// in smooth error; scaling them (Braess over-correction) cuts the iterations.
constexpr double kOvercorrect = 1.8;

struct Level {
    int nx = 0, ny = 0, nz = 0;
    std::vector<double> ax, ay, az; // face coefficients: x/y faces per slice, z faces per face index
    std::array<bool, 6> open{};
    bool wrap[2] = {false, false}; // periodic x, y: cell 0 and cell n-1 are neighbours
    std::vector<double> diag, x, b, r;
    int fx = 1, fy = 1, fz = 1; // coarsening factors to the next level
    size_t cells() const { return size_t(nx) * ny * nz; }
    size_t id(int i, int j, int k) const { return (size_t(k) * ny + j) * nx + i; }

    // (A v)_c and the off-diagonal sum for one cell.
    double offdiag(const std::vector<double>& v, int i, int j, int k) const {
        double s = 0;
        size_t c = id(i, j, k);
        if (i > 0) s += ax[size_t(k)] * v[c - 1];
        else if (wrap[0]) s += ax[size_t(k)] * v[c + size_t(nx - 1)];
        if (i < nx - 1) s += ax[size_t(k)] * v[c + 1];
        else if (wrap[0]) s += ax[size_t(k)] * v[c - size_t(nx - 1)];
        if (j > 0) s += ay[size_t(k)] * v[c - size_t(nx)];
        else if (wrap[1]) s += ay[size_t(k)] * v[c + size_t(ny - 1) * nx];
        if (j < ny - 1) s += ay[size_t(k)] * v[c + size_t(nx)];
        else if (wrap[1]) s += ay[size_t(k)] * v[c - size_t(ny - 1) * nx];
        if (k > 0) s += az[size_t(k)] * v[c - size_t(nx) * ny];
        if (k < nz - 1) s += az[size_t(k + 1)] * v[c + size_t(nx) * ny];
        return s;
    }
    void build_diag() {
        diag.assign(cells(), 0.0);
        for (int k = 0; k < nz; ++k)
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i) {
                    double d = 0;
                    d += (i > 0 || open[0] || wrap[0]) ? ax[size_t(k)] : 0.0;
                    d += (i < nx - 1 || open[1] || wrap[0]) ? ax[size_t(k)] : 0.0;
                    d += (j > 0 || open[2] || wrap[1]) ? ay[size_t(k)] : 0.0;
                    d += (j < ny - 1 || open[3] || wrap[1]) ? ay[size_t(k)] : 0.0;
                    d += (k > 0 || open[4]) ? az[size_t(k)] : 0.0;
                    d += (k < nz - 1 || open[5]) ? az[size_t(k + 1)] : 0.0;
                    diag[id(i, j, k)] = d;
                }
    }
    void apply(const std::vector<double>& v, std::vector<double>& out) const {
        parallel_for_index(nz, [&](int k) {
            for (int j = 0; j < ny; ++j) {
                const Row rw = row(v, j, k);
                const size_t c0 = id(0, j, k);
                for (int i = 0; i < nx; ++i) out[c0 + size_t(i)] = diag[c0 + size_t(i)] * v[c0 + size_t(i)] - off(rw, i, nx);
            }
        });
    }
    // One row of cells (j, k) with its neighbour rows; a missing neighbour row
    // gets coefficient 0 and points at the row itself (0 * finite adds nothing,
    // so the sums equal offdiag() term by term, in the same order). Along a
    // periodic y the first and last rows are neighbours.
    struct Row {
        const double *c, *s, *n, *d, *u;
        double ax, ay_s, ay_n, az_d, az_u;
        bool wx;
    };
    Row row(const std::vector<double>& v, int j, int k) const {
        const size_t c = id(0, j, k), pl = size_t(nx) * ny;
        Row out;
        out.c = &v[c];
        out.ax = ax[size_t(k)];
        out.wx = wrap[0];
        const std::ptrdiff_t last = std::ptrdiff_t(ny - 1) * nx;
        out.s = j > 0 ? out.c - nx : wrap[1] ? out.c + last : out.c, out.ay_s = (j > 0 || wrap[1]) ? ay[size_t(k)] : 0.0;
        out.n = j < ny - 1 ? out.c + nx : wrap[1] ? out.c - last : out.c, out.ay_n = (j < ny - 1 || wrap[1]) ? ay[size_t(k)] : 0.0;
        out.d = k > 0 ? out.c - pl : out.c, out.az_d = k > 0 ? az[size_t(k)] : 0.0;
        out.u = k < nz - 1 ? out.c + pl : out.c, out.az_u = k < nz - 1 ? az[size_t(k + 1)] : 0.0;
        return out;
    }
    static double off(const Row& r, int i, int nx_) {
        double s = 0;
        if (i > 0) s += r.ax * r.c[i - 1];
        else if (r.wx) s += r.ax * r.c[nx_ - 1];
        if (i < nx_ - 1) s += r.ax * r.c[i + 1];
        else if (r.wx) s += r.ax * r.c[0];
        s += r.ay_s * r.s[i];
        s += r.ay_n * r.n[i];
        s += r.az_d * r.d[i];
        s += r.az_u * r.u[i];
        return s;
    }
    // One red-black Gauss-Seidel half sweep over cells with (i+j+k)%2 == color.
    void gs(int color) {
        parallel_for_index(nz, [&](int k) {
            for (int j = 0; j < ny; ++j) {
                const Row rw = row(x, j, k);
                double* xr = &x[id(0, j, k)];
                const double* br = &b[id(0, j, k)];
                const double* dg = &diag[id(0, j, k)];
                for (int i = (color + j + k) & 1; i < nx; i += 2) xr[i] = (br[i] + off(rw, i, nx)) / dg[i];
            }
        });
    }
    void residual() {
        parallel_for_index(nz, [&](int k) {
            for (int j = 0; j < ny; ++j) {
                const Row rw = row(x, j, k);
                const size_t c0 = id(0, j, k);
                for (int i = 0; i < nx; ++i) r[c0 + size_t(i)] = b[c0 + size_t(i)] - (diag[c0 + size_t(i)] * x[c0 + size_t(i)] - off(rw, i, nx));
            }
        });
    }
};

bool any_open(const std::array<bool, 6>& o) { return std::find(o.begin(), o.end(), true) != o.end(); }

} // namespace

struct PressureSolver::Impl {
    GridSpec spec;
    std::vector<Level> levels;
    std::vector<double> chol; // dense Cholesky factor of the coarsest level (row-major lower)
    size_t nchol = 0;
    bool singular = false;
    std::vector<double> phi, res, z, d, q, partial, rhs;

    void coarsen() {
        while (true) {
            Level& f = levels.back();
            if (f.cells() <= 512) break;
            // Along a periodic axis only when the coarse count stays even (the
            // red-black colouring must match across the wrap); the aggregates
            // (2i, 2i+1) never straddle it, so restriction and prolongation need
            // no wrap.
            f.fx = (f.nx % (f.wrap[0] ? 4 : 2) == 0 && f.nx >= 4) ? 2 : 1;
            f.fy = (f.ny % (f.wrap[1] ? 4 : 2) == 0 && f.ny >= 4) ? 2 : 1;
            f.fz = (f.nz % 2 == 0 && f.nz >= 4) ? 2 : 1;
            if (f.fx * f.fy * f.fz == 1) break;
            Level c;
            c.nx = f.nx / f.fx;
            c.ny = f.ny / f.fy;
            c.nz = f.nz / f.fz;
            c.open = f.open;
            c.wrap[0] = f.wrap[0], c.wrap[1] = f.wrap[1];
            // Galerkin coarse operator for piecewise-constant prolongation:
            // a coarse face coefficient is the sum of the fine faces it covers.
            c.ax.assign(size_t(c.nz), 0.0);
            c.ay.assign(size_t(c.nz), 0.0);
            c.az.assign(size_t(c.nz + 1), 0.0);
            for (int K = 0; K < c.nz; ++K)
                for (int s = 0; s < f.fz; ++s) {
                    c.ax[size_t(K)] += f.fy * f.ax[size_t(K * f.fz + s)];
                    c.ay[size_t(K)] += f.fx * f.ay[size_t(K * f.fz + s)];
                }
            for (int K = 0; K <= c.nz; ++K) c.az[size_t(K)] = f.fx * f.fy * f.az[size_t(K * f.fz)];
            size_t n = c.cells();
            c.x.assign(n, 0);
            c.b.assign(n, 0);
            c.r.assign(n, 0);
            c.build_diag();
            levels.push_back(std::move(c));
        }
        Level& c = levels.back();
        if (c.cells() <= 1024) {
            nchol = c.cells();
            std::vector<double> a(nchol * nchol, 0.0);
            std::vector<double> e(nchol, 0.0), col(nchol);
            for (size_t m = 0; m < nchol; ++m) {
                e.assign(nchol, 0.0);
                e[m] = 1;
                for (int k = 0; k < c.nz; ++k)
                    for (int j = 0; j < c.ny; ++j)
                        for (int i = 0; i < c.nx; ++i) {
                            size_t id = c.id(i, j, k);
                            a[id * nchol + m] = c.diag[id] * e[id] - c.offdiag(e, i, j, k);
                        }
            }
            // Singular (closed) operator: pin cell 0 so the factor exists; the
            // preconditioner output is mean-projected afterwards.
            if (singular) a[0] += c.diag[0];
            for (size_t j = 0; j < nchol; ++j) {
                double s = a[j * nchol + j];
                for (size_t p = 0; p < j; ++p) s -= a[j * nchol + p] * a[j * nchol + p];
                if (!(s > 0)) throw Error("sim pressure: coarse operator is not positive definite");
                double l = std::sqrt(s);
                a[j * nchol + j] = l;
                for (size_t i = j + 1; i < nchol; ++i) {
                    double t = a[i * nchol + j];
                    for (size_t p = 0; p < j; ++p) t -= a[i * nchol + p] * a[j * nchol + p];
                    a[i * nchol + j] = t / l;
                }
            }
            chol = std::move(a);
        }
    }

    void coarse_solve(Level& c) {
        if (nchol) {
            std::vector<double>& x = c.x;
            for (size_t i = 0; i < nchol; ++i) {
                double t = c.b[i];
                for (size_t p = 0; p < i; ++p) t -= chol[i * nchol + p] * x[p];
                x[i] = t / chol[i * nchol + i];
            }
            for (size_t i = nchol; i-- > 0;) {
                double t = x[i];
                for (size_t p = i + 1; p < nchol; ++p) t -= chol[p * nchol + i] * x[p];
                x[i] = t / chol[i * nchol + i];
            }
        } else {
            std::fill(c.x.begin(), c.x.end(), 0.0);
            for (int s = 0; s < 20; ++s) c.gs(0), c.gs(1);
            for (int s = 0; s < 20; ++s) c.gs(1), c.gs(0);
        }
    }

    void vcycle(size_t l) {
        Level& f = levels[l];
        if (l + 1 == levels.size()) {
            coarse_solve(f);
            return;
        }
        std::fill(f.x.begin(), f.x.end(), 0.0);
        for (int s = 0; s < 2; ++s) f.gs(0), f.gs(1);
        f.residual();
        Level& c = levels[l + 1];
        // Restriction: each coarse slice sums its own fine slices (disjoint writes).
        parallel_for_index(c.nz, [&](int K) {
            std::fill(c.b.begin() + long(c.id(0, 0, K)), c.b.begin() + long(c.id(0, 0, K) + size_t(c.nx) * c.ny), 0.0);
            for (int k = K * f.fz; k < (K + 1) * f.fz; ++k)
                for (int j = 0; j < f.ny; ++j)
                    for (int i = 0; i < f.nx; ++i) c.b[c.id(i / f.fx, j / f.fy, K)] += f.r[f.id(i, j, k)];
        });
        vcycle(l + 1);
        parallel_for_index(f.nz, [&](int k) {
            for (int j = 0; j < f.ny; ++j)
                for (int i = 0; i < f.nx; ++i) f.x[f.id(i, j, k)] += kOvercorrect * c.x[c.id(i / f.fx, j / f.fy, k / f.fz)];
        });
        for (int s = 0; s < 2; ++s) f.gs(1), f.gs(0);
    }

    void remove_mean(std::vector<double>& v) {
        Level& f = levels[0];
        double m = reduce_slices(f.nz, partial, [&](int k) {
                       double s = 0;
                       for (size_t c = f.id(0, 0, k), e = c + size_t(f.nx) * f.ny; c < e; ++c) s += v[c];
                       return s;
                   }) /
                   double(f.cells());
        parallel_for_index(f.nz, [&](int k) {
            for (size_t c = f.id(0, 0, k), e = c + size_t(f.nx) * f.ny; c < e; ++c) v[c] -= m;
        });
    }

    double dot(const std::vector<double>& a, const std::vector<double>& b) {
        Level& f = levels[0];
        return reduce_slices(f.nz, partial, [&](int k) {
            double s = 0;
            for (size_t c = f.id(0, 0, k), e = c + size_t(f.nx) * f.ny; c < e; ++c) s += a[c] * b[c];
            return s;
        });
    }

    void precondition(const std::vector<double>& r, std::vector<double>& out, bool multigrid) {
        Level& f = levels[0];
        if (!multigrid) {
            for (size_t c = 0; c < r.size(); ++c) out[c] = r[c] / f.diag[c];
        } else {
            f.b = r;
            if (singular) remove_mean(f.b);
            vcycle(0);
            out = f.x;
        }
        if (singular) remove_mean(out);
    }
};

PressureSolver::PressureSolver(const GridSpec& spec, std::vector<double> rho_cell, const MemoryBudget* budget)
    : impl_(std::make_unique<Impl>()), rho_cell_(std::move(rho_cell)) {
    spec.validate();
    if (budget) budget->check(uint64_t(spec.cells()) * 88, "sim: pressure solver");
    if (rho_cell_.empty()) rho_cell_.assign(size_t(spec.nz), 1.0);
    if (rho_cell_.size() != size_t(spec.nz)) throw Error("sim pressure: rho_cell needs nz entries");
    for (double r : rho_cell_)
        if (!(r > 0) || !std::isfinite(r)) throw Error("sim pressure: rho_cell must be finite and > 0");
    rho_face_.resize(size_t(spec.nz + 1));
    for (int k = 0; k <= spec.nz; ++k)
        rho_face_[size_t(k)] = k == 0 ? rho_cell_.front() : k == spec.nz ? rho_cell_.back()
                                                            : 0.5 * (rho_cell_[size_t(k - 1)] + rho_cell_[size_t(k)]);
    auto& m = *impl_;
    m.spec = spec;
    Level l0;
    l0.nx = spec.nx;
    l0.ny = spec.ny;
    l0.nz = spec.nz;
    for (int f = 0; f < 6; ++f) l0.open[size_t(f)] = spec.face(f) == Boundary::Open;
    l0.wrap[0] = spec.periodic(0), l0.wrap[1] = spec.periodic(1);
    l0.ax = rho_cell_;
    l0.ay = rho_cell_;
    l0.az = rho_face_;
    size_t n = spec.cells();
    l0.x.assign(n, 0);
    l0.b.assign(n, 0);
    l0.r.assign(n, 0);
    l0.build_diag();
    m.singular = !any_open(l0.open);
    m.levels.push_back(std::move(l0));
    m.coarsen();
    m.phi.assign(n, 0);
    m.res.assign(n, 0);
    m.z.assign(n, 0);
    m.d.assign(n, 0);
    m.q.assign(n, 0);
}

PressureSolver::~PressureSolver() = default;
PressureSolver::PressureSolver(PressureSolver&&) noexcept = default;
PressureSolver& PressureSolver::operator=(PressureSolver&&) noexcept = default;

ProjectionReport PressureSolver::project(MacVelocity& vel, const ProjectionOptions& opt) {
    auto& m = *impl_;
    const GridSpec& s = m.spec;
    if (vel.spec.nx != s.nx || vel.spec.ny != s.ny || vel.spec.nz != s.nz)
        throw Error("sim pressure: velocity grid does not match the solver grid");
    check_option(opt.tolerance, "tolerance");
    check_option(opt.max_iterations, "max_iterations");
    if (!std::isfinite(vel.max_abs())) throw Error("sim pressure: velocity holds NaN or Inf");
    vel.enforce_walls();
    ProjectionReport rep;
    rep.levels = int(m.levels.size());
    rep.before = divergence_stats(vel, rho_cell_, rho_face_);
    const int nx = s.nx, ny = s.ny, nz = s.nz;
    Level& L = m.levels[0];
    std::vector<double>& b = L.b;
    std::vector<double>& rhs = m.rhs;
    rhs.resize(s.cells());
    parallel_for_index(nz, [&](int k) {
        double rc = rho_cell_[size_t(k)], rlo = rho_face_[size_t(k)], rhi = rho_face_[size_t(k + 1)];
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                double dv = rc * (double(vel.u[vel.iu(i + 1, j, k)]) - vel.u[vel.iu(i, j, k)]) +
                            rc * (double(vel.v[vel.iv(i, j + 1, k)]) - vel.v[vel.iv(i, j, k)]) +
                            (rhi * double(vel.w[vel.iw(i, j, k + 1)]) - rlo * double(vel.w[vel.iw(i, j, k)]));
                rhs[L.id(i, j, k)] = -dv;
            }
    });
    (void)b;
    if (m.singular) m.remove_mean(rhs);
    double bnorm = std::sqrt(m.dot(rhs, rhs));
    std::fill(m.phi.begin(), m.phi.end(), 0.0);
    if (bnorm > 0) {
        m.res = rhs;
        m.precondition(m.res, m.z, opt.multigrid);
        m.d = m.z;
        double rz = m.dot(m.res, m.z);
        double rn = bnorm;
        int it = 0;
        while (it < opt.max_iterations && rn > opt.tolerance * bnorm) {
            L.apply(m.d, m.q);
            double dq = m.dot(m.d, m.q);
            if (!(dq > 0)) break;
            double alpha = rz / dq;
            parallel_for_index(nz, [&](int k) {
                for (size_t c = L.id(0, 0, k), e = c + size_t(nx) * ny; c < e; ++c) {
                    m.phi[c] += alpha * m.d[c];
                    m.res[c] -= alpha * m.q[c];
                }
            });
            ++it;
            rn = std::sqrt(m.dot(m.res, m.res));
            if (rn <= opt.tolerance * bnorm) break;
            m.precondition(m.res, m.z, opt.multigrid);
            double rz2 = m.dot(m.res, m.z);
            double beta = rz2 / rz;
            rz = rz2;
            parallel_for_index(nz, [&](int k) {
                for (size_t c = L.id(0, 0, k), e = c + size_t(nx) * ny; c < e; ++c) m.d[c] = m.z[c] + beta * m.d[c];
            });
        }
        rep.iterations = it;
        rep.relative_residual = rn / bnorm;
        rep.converged = rn <= opt.tolerance * bnorm;
    } else {
        rep.converged = true;
    }
    if (m.singular) m.remove_mean(m.phi);
    // u -= grad phi (phi absorbs dt / rho and dx); open faces see phi = 0
    // outside, periodic ones the cell across the wrap (faces 0 and n get the
    // same update).
    const auto& phi = m.phi;
    auto P = [&](int i, int j, int k) -> double {
        if (L.wrap[0]) i = i < 0 ? i + nx : i >= nx ? i - nx : i;
        if (L.wrap[1]) j = j < 0 ? j + ny : j >= ny ? j - ny : j;
        if (i < 0 || i >= nx || j < 0 || j >= ny || k < 0 || k >= nz) return 0.0;
        return phi[L.id(i, j, k)];
    };
    const bool keep_x0 = L.open[0] || L.wrap[0], keep_x1 = L.open[1] || L.wrap[0];
    const bool keep_y0 = L.open[2] || L.wrap[1], keep_y1 = L.open[3] || L.wrap[1];
    parallel_for_index(nz, [&](int k) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i <= nx; ++i) {
                if ((i == 0 && !keep_x0) || (i == nx && !keep_x1)) continue;
                vel.u[vel.iu(i, j, k)] -= float(P(i, j, k) - P(i - 1, j, k));
            }
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i < nx; ++i) {
                if ((j == 0 && !keep_y0) || (j == ny && !keep_y1)) continue;
                vel.v[vel.iv(i, j, k)] -= float(P(i, j, k) - P(i, j - 1, k));
            }
    });
    parallel_for_index(nz + 1, [&](int k) {
        if ((k == 0 && !L.open[4]) || (k == nz && !L.open[5])) return;
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) vel.w[vel.iw(i, j, k)] -= float(P(i, j, k) - P(i, j, k - 1));
    });
    rep.after = divergence_stats(vel, rho_cell_, rho_face_);
    return rep;
}

} // namespace atlas::sim
