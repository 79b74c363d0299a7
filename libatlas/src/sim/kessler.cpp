// Kessler warm rain: conversions, evaporation, sedimentation (see kessler.h).
#include "atlas/sim/kessler.h"

#include "atlas/core/error.h"
#include "atlas/sim/sim_options.h"
#include "atlas/sim/thermo.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace atlas::sim {
namespace {

void check(double v, double lo, double hi, const char* what) {
    if (!(v >= lo && v <= hi)) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "sim kessler: %s = %g, expected %g..%g", what, v, lo, hi);
        throw Error(buf);
    }
}

// Member `member` against the bounds of its node option rain_<member> (sim_options.h).
void check_option(double v, const std::string& member) {
    const TextOption<SimOptions>& o = sim_option("rain_" + member);
    check(v, o.min, o.max, (member + " (" + o.unit + ")").c_str());
}

void check_finite(std::span<const float> a, const char* what) {
    for (size_t n = 0; n < a.size(); ++n)
        if (!std::isfinite(a[n]))
            throw Error(std::string("sim kessler: ") + what + " holds NaN/Inf at cell " + std::to_string(n));
}

void check_sizes(const GridSpec& s, size_t n, size_t nrho) {
    if (n != s.cells()) throw Error("sim kessler: fields need one value per cell");
    if (nrho != size_t(s.nz)) throw Error("sim kessler: reference profiles need nz entries");
}

} // namespace

void KesslerOptions::validate() const {
    check_option(autoconversion_rate, "autoconversion_rate");
    check_option(autoconversion_threshold, "autoconversion_threshold");
    check_option(accretion_rate, "accretion_rate");
    if (!(sedimentation_cfl > 0 && sedimentation_cfl <= 1)) check(sedimentation_cfl, 1e-9, 1, "sedimentation_cfl");
}

double rain_fall_speed(double qr, double rho, double rho_surface) {
    if (!(qr > 0)) return 0.0;
    // The fit wants rho qr in g/cm^3 (1 kg/m^3 = 1e-3 g/cm^3).
    return 36.34 * std::pow(1e-3 * rho * qr, 0.1364) * std::sqrt(rho_surface / rho);
}

double rain_evaporation_rate(double qv, double qr, double qvs, double rho, double p) {
    if (!(qr > 0) || !(qvs > 0) || qv >= qvs) return 0.0;
    const double rg = 1e-3 * rho, pmb = 1e-2 * p, rq = rg * qr;
    const double vent = 1.6 + 124.9 * std::pow(rq, 0.2046);
    return (1 - qv / qvs) * vent * std::pow(rq, 0.525) / (rg * (5.4e5 + 2.55e6 / (pmb * qvs)));
}

KesslerReport kessler_conversions(const GridSpec& s, std::span<float> theta, std::span<float> qv, std::span<float> qc,
                                  std::span<float> qr, const std::vector<double>& pressure,
                                  const std::vector<double>& exner, const std::vector<double>& rho, double dt,
                                  const KesslerOptions& o) {
    o.validate();
    check_sizes(s, theta.size(), pressure.size());
    check_sizes(s, qv.size(), exner.size());
    check_sizes(s, qc.size(), rho.size());
    check_sizes(s, qr.size(), size_t(s.nz));
    if (!std::isfinite(dt) || dt < 0) throw Error("sim kessler: dt must be finite and >= 0 s");
    check_finite(theta, "theta");
    check_finite(qv, "qv");
    check_finite(qc, "qc");
    check_finite(qr, "qr");
    const size_t plane = size_t(s.nx) * s.ny;
    std::vector<double> au(size_t(s.nz)), ac(size_t(s.nz)), ev(size_t(s.nz));
    parallel_for_index(s.nz, [&](int k) {
        const double p = pressure[size_t(k)], pi = exner[size_t(k)], r = rho[size_t(k)];
        double sa = 0, sc = 0, se = 0;
        for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c) {
            // Conversions: exact over dt for frozen qr (bounded for any k dt).
            const double q0 = std::max(0.f, qc[c]), r0 = std::max(0.f, qr[c]);
            const double lacc = o.accretion_rate * std::pow(r0, 0.875);
            const bool auto_on = q0 > o.autoconversion_threshold && o.autoconversion_rate > 0;
            const double lam = lacc + (auto_on ? o.autoconversion_rate : 0.0);
            if (lam > 0 && q0 > 0) {
                const double qstar = auto_on ? o.autoconversion_rate * o.autoconversion_threshold / lam : 0.0;
                const double q1 = qstar + (q0 - qstar) * std::exp(-lam * dt);
                const float qcn = std::clamp(float(q1), 0.f, qc[c]);
                const float moved = qc[c] - qcn;
                qc[c] = qcn;
                qr[c] += moved;
                const double ra = auto_on ? o.autoconversion_rate * (q0 - o.autoconversion_threshold) : 0.0;
                const double share = ra / (ra + lacc * q0);
                sa += moved * share;
                sc += moved * (1 - share);
            }
            // Evaporation of rain in subsaturated air, capped by qr and by the
            // deficit that would saturate the cell (cooling lowers q_s).
            if (o.evaporation && qr[c] > 0) {
                const double T = double(theta[c]) * pi;
                const double qvs = saturation_mixing_ratio(T, p);
                const double e = rain_evaporation_rate(qv[c], qr[c], qvs, r, p);
                if (e > 0) {
                    const double cap = (qvs - qv[c]) / (1 + kLv * kLv * qvs / (kCp * kRv * T * T));
                    const float d = float(std::min({e * dt, double(qr[c]), cap}));
                    if (d > 0) {
                        qr[c] -= d;
                        qv[c] += d;
                        theta[c] -= float(kLv * d / (kCp * pi));
                        se += d;
                    }
                }
            }
        }
        au[size_t(k)] = sa, ac[size_t(k)] = sc, ev[size_t(k)] = se;
    });
    KesslerReport rep;
    for (int k = 0; k < s.nz; ++k) rep.autoconverted += au[size_t(k)], rep.accreted += ac[size_t(k)], rep.evaporated += ev[size_t(k)];
    return rep;
}

KesslerReport rain_sedimentation(const GridSpec& s, std::span<float> qr, const std::vector<double>& rho, double dt,
                                 const KesslerOptions& o) {
    o.validate();
    check_sizes(s, qr.size(), rho.size());
    if (!std::isfinite(dt) || dt < 0) throw Error("sim kessler: dt must be finite and >= 0 s");
    check_finite(qr, "qr");
    KesslerReport rep;
    const int nx = s.nx, ny = s.ny, nz = s.nz;
    const size_t plane = size_t(nx) * ny;
    const double dz = s.dx, area = s.dx * s.dx, rs = rho[0];
    std::vector<double> vmax(static_cast<size_t>(nz)), out(static_cast<size_t>(ny));
    double remaining = dt;
    while (remaining > 1e-12 * dt && dt > 0) {
        parallel_for_index(nz, [&](int k) {
            double m = 0;
            for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c)
                m = std::max(m, rain_fall_speed(qr[c], rho[size_t(k)], rs));
            vmax[size_t(k)] = m;
        });
        double vm = *std::max_element(vmax.begin(), vmax.end());
        rep.max_fall_speed = std::max(rep.max_fall_speed, vm);
        if (vm <= 0) break;
        const double sdt = std::min(remaining, o.sedimentation_cfl * dz / vm);
        if (++rep.sedimentation_substeps > 100000) throw Error("sim kessler: sedimentation needs more than 100000 substeps");
        // Rows of x are independent columns: parallel over y rows, each
        // column swept bottom-up so every cell reads the pre-step flux above it.
        parallel_for_index(ny, [&](int j) {
            double lost = 0;
            for (int i = 0; i < nx; ++i) {
                size_t c0 = size_t(j) * nx + i;
                double flux_below = 0; // rho V qr at the bottom face of the cell being updated (old state)
                {
                    const double q = qr[c0];
                    flux_below = rho[0] * rain_fall_speed(q, rho[0], rs) * q;
                }
                lost += flux_below * sdt * area;
                for (int k = 0; k < nz; ++k) {
                    const size_t c = c0 + size_t(k) * plane;
                    double above = 0;
                    if (k + 1 < nz) {
                        const double q = qr[c + plane];
                        above = rho[size_t(k + 1)] * rain_fall_speed(q, rho[size_t(k + 1)], rs) * q;
                    }
                    const double mass = rho[size_t(k)] * qr[c] + sdt / dz * (above - flux_below);
                    qr[c] = float(std::max(mass, 0.0) / rho[size_t(k)]);
                    flux_below = above;
                }
            }
            out[size_t(j)] += lost;
        });
        remaining -= sdt;
    }
    for (double l : out) rep.fallout += l;
    return rep;
}

} // namespace atlas::sim
