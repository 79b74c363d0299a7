// The SimOptions schema (atlas/sim/sim_options.h).
#include "atlas/sim/sim_options.h"

#include "atlas/core/error.h"

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace atlas::sim {

namespace {

using K = OptionKind;
using S = SimOptions;
using V = OptionValue;

// An option's member as a path of member pointers from SimOptions: s.*P1.*P2 for
// kessler and projection members (a fold over .*), so each option names its member once.
template <auto... Path>
auto& member(S& s) {
    return (s .* ... .* Path);
}
template <auto... Path>
const auto& member(const S& s) {
    return (s .* ... .* Path);
}

template <auto... Path>
void set_number(S& s, const V& v) {
    auto& m = member<Path...>(s);
    m = static_cast<std::remove_reference_t<decltype(m)>>(v.number);
}
template <auto... Path>
V number_of(const S& s) {
    V v;
    v.number = double(member<Path...>(s));
    return v;
}
template <auto... Path>
void set_flag(S& s, const V& v) {
    member<Path...>(s) = v.flag;
}
template <auto... Path>
V flag_of(const S& s) {
    V v;
    v.flag = member<Path...>(s);
    return v;
}

// Enumerations as the words the node takes, in its choice order.
constexpr std::pair<const char*, TimeScheme> kTimeSchemes[] = {{"trapezoidal", TimeScheme::Trapezoidal}, {"split", TimeScheme::Split}};
constexpr std::pair<const char*, AdvectionScheme> kAdvectionSchemes[] = {
    {"maccormack", AdvectionScheme::MacCormack}, {"semi_lagrangian", AdvectionScheme::SemiLagrangian}, {"cubic_limited", AdvectionScheme::CubicLimited}};

template <auto Member, const auto& Words>
void set_word(S& s, const V& v) {
    for (const auto& [word, value] : Words)
        if (v.word == word) s.*Member = value;
}
template <auto Member, const auto& Words>
V word_of(const S& s) {
    V v;
    for (const auto& [word, value] : Words)
        if (s.*Member == value) v.word = word;
    return v;
}
template <const auto& Words>
std::vector<std::string> words() {
    std::vector<std::string> w;
    for (const auto& pair : Words) w.emplace_back(pair.first);
    return w;
}

TextOption<S> option(TextOptionSpec spec, void (*apply)(S&, const V&), V (*value_of)(const S&)) {
    TextOption<S> o{std::move(spec)};
    o.apply = apply;
    o.value_of = value_of;
    o.default_text = option_value_text(o, value_of(S{})); // the struct's member initializer
    return o;
}
template <auto... Path>
TextOption<S> number(const char* name, double min, double max, const char* unit, std::string doc) {
    return option({.name = name, .metavar = "", .kind = K::Number, .doc = std::move(doc), .min = min, .max = max, .unit = unit},
                  &set_number<Path...>, &number_of<Path...>);
}
template <auto... Path>
TextOption<S> integer(const char* name, double min, double max, std::string doc) {
    return option({.name = name, .metavar = "", .kind = K::Integer, .doc = std::move(doc), .min = min, .max = max},
                  &set_number<Path...>, &number_of<Path...>);
}
template <auto... Path>
TextOption<S> flag(const char* name, std::string doc) {
    return option({.name = name, .metavar = "", .kind = K::Flag, .doc = std::move(doc)}, &set_flag<Path...>, &flag_of<Path...>);
}
template <auto Member, const auto& Words>
TextOption<S> choice(const char* name, std::string doc) {
    return option({.name = name, .metavar = "", .kind = K::Choice, .doc = std::move(doc), .words = words<Words>()},
                  &set_word<Member, Words>, &word_of<Member, Words>);
}

std::vector<TextOption<S>> make_sim_options() {
    using KO = KesslerOptions;
    using PO = ProjectionOptions;
    return {
        number<&S::cfl>("cfl", 0.1, 5, "cells", "max cells travelled per substep"),
        choice<&S::time_scheme, kTimeSchemes>(
            "time_scheme", "trapezoidal: second-order (forces half at the departure, half at the arrival point, time-centred "
                           "trajectories; 24 B more per cell); split: the first-order advect-then-project split"),
        number<&S::step_error_tolerance>("step_error_tolerance", 0, 1, "cells",
                                         "accuracy step control (trapezoidal): substeps are shortened so the embedded back-trace error "
                                         "estimate stays below this (0 = CFL limits only); reported per step as step_error"),
        integer<&S::max_substeps>("max_substeps", 1, 10000, "substep budget per step (more is an error naming the node)"),
        choice<&S::scheme, kAdvectionSchemes>(
            "scheme", "advection scheme: maccormack (limited), semi_lagrangian (trilinear, most diffusive), cubic_limited "
                      "(Catmull-Rom read clamped to its 8 neighbours: one read, less smearing)"),
        flag<&S::advection_reflection>("advection_reflection",
                                       "advection-reflection stepping (Zehnder et al. 2018): keeps kinetic energy; a second projection "
                                       "per substep and 12 B more per cell"),
        flag<&S::reversible_theta_e>("reversible_theta_e",
                                     "Bryan & Fritsch reversible thermodynamics: the saturation adjustment keeps theta_e (liquid heat "
                                     "capacity counted) instead of theta_l; a saturated sounding (total_water > 0) is built with the "
                                     "linearised adjustment, so it is not exactly neutral in this mode"),
        flag<&S::rain>("rain", "Kessler warm rain (needs moist): autoconversion, accretion, evaporation and fallout through the floor; "
                               "rain loads the buoyancy; 8 B more per cell; output 'rain'"),
        number<&S::kessler, &KO::autoconversion_rate>("rain_autoconversion_rate", 0, 1, "1/s",
                                                      "Kessler k1: cloud water to rain above the threshold"),
        number<&S::kessler, &KO::autoconversion_threshold>("rain_autoconversion_threshold", 0, 0.01, "kg/kg",
                                                           "Kessler a: cloud water needed before rain forms"),
        number<&S::kessler, &KO::accretion_rate>("rain_accretion_rate", 0, 100, "1/s", "Kessler k2: collection of cloud water by rain"),
        flag<&S::kessler, &KO::evaporation>("rain_evaporation", "rain evaporates in subsaturated air (cooling it)"),
        flag<&S::kessler, &KO::sedimentation>("rain_sedimentation", "rain falls at its terminal speed and leaves through the floor"),
        flag<&S::anelastic>("anelastic", "false: Boussinesq (constant reference density)"),
        flag<&S::moist>("moist", "false: dry (vapour and cloud water are passive)"),
        number<&S::projection, &PO::tolerance>("pressure_tolerance", 1e-12, 0.1, "", "relative residual of the pressure solve"),
        integer<&S::projection, &PO::max_iterations>("pressure_max_iterations", 1, 10000, "CG iteration cap per projection"),
        flag<&S::projection, &PO::multigrid>("multigrid", "multigrid-preconditioned CG (false: Jacobi-preconditioned)"),
        number<&S::condensation_rate>("condensation_rate", 0, 1e9, "1/s", "0: instantaneous saturation adjustment"),
        number<&S::vorticity_confinement>("vorticity_confinement", 0, 0.2, "",
                                          "dimensionless epsilon of vorticity confinement, f = eps dx |omega| (N x omega) (billowy "
                                          "detail; 0.1..0.2 typical)"),
        number<&S::viscosity>("viscosity", 0, 1e4, "m^2/s", "explicit kinematic viscosity"),
        number<&S::diffusivity>("diffusivity", 0, 1e4, "m^2/s", "explicit diffusivity of theta', qv, qc"),
    };
}

} // namespace

std::span<const TextOption<SimOptions>> sim_options() {
    static const std::vector<TextOption<SimOptions>> options = make_sim_options();
    return options;
}

const TextOption<SimOptions>& sim_option(std::string_view name) {
    if (const TextOption<SimOptions>* o = find_option(sim_options(), name)) return *o;
    throw Error("sim: no solver option '" + std::string(name) + "'");
}

} // namespace atlas::sim
