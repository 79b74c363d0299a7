// Bolton saturation and Newton saturation adjustment (see thermo.h).
#include "atlas/sim/thermo.h"

#include "atlas/core/error.h"

#include <algorithm>
#include <cmath>

namespace atlas::sim {

double saturation_vapor_pressure(double T) {
    T = std::max(T, 100.0);
    return 611.2 * std::exp(17.67 * (T - 273.15) / (T - 29.65));
}

double saturation_mixing_ratio(double T, double p) {
    double es = std::min(saturation_vapor_pressure(T), 0.5 * p);
    return kEps * es / (p - es);
}

double exner(double p) { return std::pow(p / kP00, kRd / kCp); }

double equivalent_potential_temperature(double T, double p, double qv, double qt) {
    const double c = kCp + 4186.0 * qt;
    const double e = p * qv / (kEps + qv);
    return T * std::pow((p - e) / kP00, -kRd / c) * std::exp(kLv * qv / (c * T));
}

double temperature_from_theta_e(double theta_e, double p, double qv, double qt) {
    // ln theta_e is increasing in T (d/dT = (1 - L qv / (c T)) / T > 0 for qv < 0.1).
    double lo = 100, hi = 500, T = std::clamp(theta_e * exner(p), lo, hi);
    const double target = std::log(theta_e);
    for (int it = 0; it < 100; ++it) {
        const double f = std::log(equivalent_potential_temperature(T, p, qv, qt)) - target;
        if (std::fabs(f) < 1e-15) break;
        (f > 0 ? hi : lo) = T;
        const double c = kCp + 4186.0 * qt;
        const double df = (1 - kLv * qv / (c * T)) / T;
        double next = T - f / df;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (std::fabs(next - T) < 1e-12 * T) {
            T = next;
            break;
        }
        T = next;
    }
    return T;
}

double equilibrium_temperature_theta_e(double theta_e, double p, double qt, double T_guess) {
    // g(T) = ln theta_e(T, min(qt, qs(T)), qt) - ln theta_e is increasing in T
    // (the saturated and unsaturated branches both increase and meet
    // continuously): safeguarded Newton with a bisection fallback.
    double lo = 100, hi = 500;
    const double target = std::log(theta_e);
    auto g = [&](double T) {
        return std::log(equivalent_potential_temperature(T, p, std::min(qt, saturation_mixing_ratio(T, p)), qt)) - target;
    };
    double T = std::clamp(T_guess, lo + 1, hi - 1);
    for (int it = 0; it < 100; ++it) {
        const double f = g(T);
        if (std::fabs(f) < 1e-15) break;
        (f > 0 ? hi : lo) = T;
        const double h = 1e-4;
        const double df = (g(T + h) - g(T - h)) / (2 * h);
        double next = df > 0 ? T - f / df : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        const bool done = std::fabs(next - T) < 1e-12 * T || hi - lo < 1e-12 * T;
        T = next;
        if (done) break;
    }
    return T;
}

AdjustResult saturation_adjust_theta_e(double theta, double qv, double qc, double p, double relax) {
    if (!std::isfinite(theta) || !std::isfinite(qv) || !std::isfinite(qc) || !std::isfinite(p) || !std::isfinite(relax))
        throw Error("sim saturation_adjust_theta_e: non-finite theta, qv, qc, p or relax");
    if (!(p > 0)) throw Error("sim saturation_adjust_theta_e: pressure must be > 0 Pa");
    if (!(theta > 0)) throw Error("sim saturation_adjust_theta_e: theta must be > 0 K");
    qv = std::max(qv, 0.0);
    qc = std::max(qc, 0.0);
    relax = std::clamp(relax, 0.0, 1.0);
    const double pi = exner(p), qt = qv + qc;
    const double the = equivalent_potential_temperature(theta * pi, p, qv, qt);
    const double T = equilibrium_temperature_theta_e(the, p, qt, theta * pi);
    AdjustResult r{theta, qv, qc, 0.0, 0};
    const double qv_eq = std::min(qt, saturation_mixing_ratio(T, p));
    double d = relax * (qv - qv_eq); // condensed amount
    d = std::clamp(d, -qc, qv);
    r.qv = qv - d;
    r.qc = qc + d;
    r.condensed = d;
    const double Tn = relax >= 1 ? T : temperature_from_theta_e(the, p, r.qv, qt);
    r.theta = Tn / pi;
    return r;
}

AdjustResult saturation_adjust(double theta, double qv, double qc, double p, double relax) {
    if (!std::isfinite(theta) || !std::isfinite(qv) || !std::isfinite(qc) || !std::isfinite(p) || !std::isfinite(relax))
        throw Error("sim saturation_adjust: non-finite theta, qv, qc, p or relax");
    if (!(p > 0)) throw Error("sim saturation_adjust: pressure must be > 0 Pa");
    if (!(theta > 0)) throw Error("sim saturation_adjust: theta must be > 0 K");
    qv = std::max(qv, 0.0);
    qc = std::max(qc, 0.0);
    relax = std::clamp(relax, 0.0, 1.0);
    const double pi = exner(p), T0 = theta * pi, k = kLv / kCp;
    auto f = [&](double d) { return qv - d - saturation_mixing_ratio(T0 + k * d, p); };
    AdjustResult r{theta, qv, qc, 0.0, 0};
    double lo = -qc, hi = qv;
    if (f(lo) <= 0) {
        r.condensed = lo; // sub-saturated even with all cloud evaporated
    } else {
        // f is decreasing in d with f(lo) > 0 >= f(hi): Newton, kept inside [lo, hi].
        double d = std::clamp(0.0, lo, hi);
        for (int it = 0; it < 60; ++it) {
            r.iterations = it + 1;
            double T = T0 + k * d;
            double fd = f(d);
            if (fd > 0) lo = d; else hi = d;
            if (std::fabs(fd) <= 1e-14 + 1e-12 * qv || hi - lo <= 1e-16) break;
            double h = std::max(1e-6 * T, 1e-3);
            double dqs = (saturation_mixing_ratio(T + h, p) - saturation_mixing_ratio(T - h, p)) / (2 * h);
            double next = d - fd / (-1.0 - dqs * k);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            d = next;
        }
        r.condensed = d;
    }
    double d = relax * r.condensed;
    d = std::clamp(d, -qc, qv);
    r.qv = qv - d;
    r.qc = qc + d;
    r.theta = theta + k * d / pi;
    r.condensed = d;
    return r;
}

} // namespace atlas::sim
