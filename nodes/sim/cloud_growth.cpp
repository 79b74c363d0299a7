// sim/cloud_growth: runs the cloud-growth solver (atlas::sim::Simulation) and
// returns cloud water as density, optional extra fields, and a frame sequence
// for the 'vdb-sequence' output format. The node is a thin adapter: the
// physics is in libatlas/sim (docs/solver.md).
#include "atlas/graph/option_params.h"
#include "atlas/sim/resample.h"
#include "atlas/sim/sequence.h"
#include "atlas/sim/sim_options.h"
#include "atlas/sim/simulation.h"
#include "atlas/sim/sounding_options.h"
#include "sim_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace {
using namespace atlas;

const std::vector<std::string> kSequenceGrids = {"density", "temperature", "vapor", "vel"};

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("the solver couples the whole domain (pressure, advection)"));
    d.doc("Grows clouds by simulating rising moist air (anelastic, MAC grid, MacCormack or semi-Lagrangian or limited cubic advection, optional Kessler warm rain, "
          "multigrid-preconditioned CG projection, saturation adjustment; see docs/solver.md). The grid has 'resolution' "
          "cubic cells of 'dx' metres with its minimum corner at 'origin'. Runs ceil(duration / frame_dt) steps of frame_dt, "
          "each split into CFL-limited substeps. Sources: the optional 'emitter' field (sim/emitter; sampled at cell "
          "centres: copied when its cells line up with the grid's, else trilinear; zero outside it), a built-in noise-modulated ground patch (patch_radius > 0) and an initial warm "
          "bubble (bubble_theta != 0). Outputs cloud water as 'out' (channel 'density', kg/kg), temperature, vapour, "
          "velocity at cell centres, and 'sequence': every sequence_every-th frame's chosen grids as channels "
          "'NNNN:GRID' for the 'vdb-sequence' format. Each step's divergence (L2, max), pressure iterations, water "
          "and theta_l drift across the saturation adjustment and seconds per stage go into the cook report as "
          "'step_NNNN.*' metrics, with totals and maxima, and the cloud base and top (m above the floor, qc > 1e-5; -1: no cloud). Initial state: optional inputs initial_theta (theta' or T'), initial_vapour (qv'), initial_velocity, an ellipsoidal cos^2 bubble. Time stepping: second-order trapezoidal (default) with an accuracy step control (step_error_tolerance; step_NNNN.step_error in the report) or the first-order split. Memory (simulation_bytes: 216 B per cell, +24 with the trapezoidal time scheme, +8 with rain, +12 with advection_reflection instead, plus outputs) is checked before allocating.");
    d.input("sounding", PortType::Field2D, "sim/sounding record (default: the sim/sounding defaults)").optional = true;
    d.input("emitter", PortType::Field3D, "heat (K/s, < 0 cools) and vapour (kg/kg/s) rates, e.g. sim/emitter; channels 'heat' and 'vapour' or 0 and 1").optional = true;
    d.input("initial_theta", PortType::Field3D,
            "initial perturbation added to the sounding: potential temperature theta' in K (channel 0), or absolute "
            "temperature T' in K when initial_is_temperature (converted theta' = T' / Pi0(z)); sampled at cell centres like "
            "the emitter, zero outside it").optional = true;
    d.input("initial_vapour", PortType::Field3D,
            "initial water-vapour perturbation qv' in kg/kg (channel 0) added to the sounding's qv; a negative total is an "
            "error naming the node").optional = true;
    d.input("initial_velocity", PortType::Field3D,
            "initial velocity u, v, w in m/s at cell centres (channels 'vel.x', 'vel.y', 'vel.z' or 0, 1, 2), averaged onto "
            "the faces; closed faces get 0 and the first projection removes any divergence").optional = true;
    d.output("out", PortType::Field3D, "cloud water mixing ratio after the last step, channel 'density', kg/kg");
    d.output("temperature", PortType::Field3D, "absolute temperature after the last step, channel 'temperature', K");
    d.output("vapour", PortType::Field3D, "water-vapour mixing ratio after the last step, channel 'vapor', kg/kg");
    d.output("velocity", PortType::Field3D, "velocity at cell centres after the last step, channels 'vel.x', 'vel.y', 'vel.z', m/s");
    d.output("rain", PortType::Field3D, "rain-water mixing ratio after the last step, channel 'rain', kg/kg (zeros unless 'rain' is on)");
    d.output("sequence", PortType::Field3D, "frames for the 'vdb-sequence' format: channels 'NNNN:GRID', NNNN = 1, 2, ...");
    d.param_int3("resolution", {{64, 64, 64}}).range(1, 4096).with_unit("cells").describe("cells along x, y, z (at least 2 along two axes)").follows_proxy(ProxyScale::Cells);
    d.param_float("dx", 40).range(1e-3, 1e5).with_unit("m").describe("cubic cell edge; the top cell centre, (nz - 1/2) dx, must lie inside the modelled atmosphere (Exner > 0.05, about 29 km for 300 K), else an error names that height").follows_proxy(ProxyScale::CellSize);
    d.param_float3("origin", {{0, 0, 0}}).with_unit("m").describe("world position of the grid's minimum corner");
    d.param_enum("boundary", {"closed", "open_top", "open_sides_top", "open_sides"}, "closed")
        .describe("closed: free-slip walls everywhere; open_top: the top is open; open_sides_top: only the floor is a wall; "
                  "open_sides: free-slip floor and lid, open (ambient-pressure) x and y faces");
    d.param_enum("boundary_x", {"as_boundary", "closed", "open", "periodic"}, "as_boundary")
        .describe("both x faces: as_boundary (what 'boundary' says), closed (free-slip walls), open (ambient pressure), "
                  "periodic (x- glued to x+: what leaves one side enters the other; needs an even resolution x; the "
                  "built-in patch, the bubble, the emitter and initial inputs wrap too)");
    d.param_enum("boundary_y", {"as_boundary", "closed", "open", "periodic"}, "as_boundary")
        .describe("both y faces, as boundary_x (periodic needs an even resolution y; a one-cell-thick y is a 2D slab "
                  "and stays closed)");
    d.param_float("duration", 300).range(1e-6, 1e7).with_unit("s").describe("simulated time");
    d.param_float("frame_dt", 10).range(1e-6, 1e5).with_unit("s").describe("time per step (one report row, one potential sequence frame)");
    // The solver's options: names, defaults, ranges, units and docs are the library's
    // schema (sim_options.h), which SimOptions::validate checks too.
    declare_text_options(d, sim::sim_options());
    d.param_float("wind", 0).range(-sim::kSimMaxWind, sim::kSimMaxWind).with_unit("m/s").describe("ambient x wind at the ground");
    d.param_float("wind_shear", 0).range(-1, 1).with_unit("1/s").describe("change of the x wind per metre of height");
    d.param_float("patch_radius", 0).range(0, 1e9).with_unit("m").describe("built-in ground patch radius (0 = none)");
    d.param_float2("patch_center", {{0, 0}}).with_unit("m").describe("world x, y of the patch centre");
    d.param_float("patch_depth", 200).range(1e-3, 1e9).with_unit("m").describe("heated depth above the floor");
    d.param_float("patch_heat_rate", 0.01).range(-10, 10).with_unit("K/s").describe("heat source at the patch centre (< 0: a cooling patch)");
    d.param_float("patch_vapour_rate", 0).range(0, 1e-3).with_unit("kg/kg/s").describe("vapour source at the patch centre");
    d.param_float("patch_noise_scale", 200).range(1e-3, 1e9).with_unit("m").describe("feature size of the patch's noise");
    d.param_float("patch_noise_amount", 0.5).range(0, 1).describe("0 = smooth patch, 1 = fully noise-modulated");
    d.param_int("seed", 1).range(0, 4294967295.0).describe("seed of the patch noise");
    d.param_float("bubble_theta", 0).range(-20, 20).with_unit("K").describe("initial cos^2 warm bubble amplitude (0 = none)");
    d.param_float3("bubble_center", {{0, 0, 500}}).with_unit("m").describe("world centre of the bubble");
    d.param_float("bubble_radius", 500).range(1e-3, 1e9).with_unit("m").describe("bubble radius (a sphere unless bubble_radii is set)");
    d.param_float3("bubble_radii", {{0, 0, 0}}).with_unit("m")
        .describe("ellipsoid semi-axes along x, y, z (all > 0 to use; else the sphere of bubble_radius); the profile is "
                  "amp (1 + cos(pi l)) / 2 = amp cos^2(pi l / 2) for l = |(x - c) / r| < 1");
    d.param_bool("bubble_is_temperature", false)
        .describe("bubble_theta is an absolute-temperature perturbation T' (K), converted to theta' = T' / Pi0(z) per level "
                  "(e.g. Straka's -15 K density current); false: a potential-temperature perturbation theta'");
    d.param_bool("initial_is_temperature", false).describe("input 'initial_theta' holds T' (K) instead of theta'");
    d.param_int("sequence_every", 0).range(0, 100000).describe("keep every K-th step as a sequence frame (0: only the last)");
    d.param_string("sequence_grids", "density").describe("comma-separated grids per frame: density, temperature, vapor, vel");
}

std::vector<std::string> split_grids(const CookContext& ctx) {
    std::vector<std::string> out;
    std::stringstream in(ctx.get_string("sequence_grids"));
    std::string item;
    while (std::getline(in, item, ',')) {
        item.erase(0, item.find_first_not_of(" \t"));
        item.erase(item.find_last_not_of(" \t") + 1);
        if (item.empty()) continue;
        if (std::find(kSequenceGrids.begin(), kSequenceGrids.end(), item) == kSequenceGrids.end())
            ctx.fail("parameter 'sequence_grids': unknown grid '" + item + "' (known: density, temperature, vapor, vel)");
        if (std::find(out.begin(), out.end(), item) != out.end()) ctx.fail("parameter 'sequence_grids': '" + item + "' is listed twice");
        out.push_back(item);
    }
    if (out.empty()) ctx.fail("parameter 'sequence_grids' names no grid (use density, temperature, vapor, vel)");
    return out;
}

sim::SimOptions options_from(const CookContext& ctx, int nz, double dx) {
    sim::SimOptions o;
    read_text_options(ctx, sim::sim_options(), o);
    const double wind = ctx.get_float("wind"), shear = ctx.get_float("wind_shear");
    if (wind != 0 || shear != 0)
        for (int k = 0; k < nz; ++k) o.wind.push_back(std::clamp(wind + shear * (k + 0.5) * dx, -sim::kSimMaxWind, sim::kSimMaxWind));
    return o;
}

// A field on the solver's grid (sim::resample_to_grid), its errors naming the input.
std::vector<float> on_grid(const CookContext& ctx, const Field3D& e, int c, const sim::GridSpec& s, const Vec3d& origin,
                           const std::string& port) {
    try {
        return sim::resample_to_grid(e, c, s, origin);
    } catch (const Error& err) {
        ctx.fail("input '" + port + "' " + err.what());
    }
}

void apply_emitter(CookContext& ctx, sim::Simulation& sim, const Vec3d& origin) {
    const Field3DPtr e = ctx.input_field3d("emitter");
    int hc = e->find_channel("heat"), vc = e->find_channel("vapour");
    if (hc < 0) hc = 0;
    if (vc < 0) vc = e->channels() > 1 ? 1 : -1;
    const sim::GridSpec& s = sim.spec();
    std::vector<float> heat = on_grid(ctx, *e, hc, s, origin, "emitter");
    std::vector<float> vap = vc >= 0 ? on_grid(ctx, *e, vc, s, origin, "emitter") : std::vector<float>(s.cells(), 0.f);
    sim.set_sources(std::move(heat), std::move(vap), "node '" + ctx.node_name() + "' input 'emitter'");
}

// theta' per cell from T' per cell: theta' = T' / Pi0(z).
void to_theta(std::vector<float>& d, const sim::Simulation& sim) {
    const size_t plane = size_t(sim.spec().nx) * size_t(sim.spec().ny);
    for (size_t c = 0; c < d.size(); ++c) d[c] = float(d[c] / sim.reference().exner[c / plane]);
}

// Initial-state inputs: theta' (or T'), qv', velocity at cell centres.
void apply_initial_state(CookContext& ctx, sim::Simulation& sim, const Vec3d& origin) {
    const sim::GridSpec& s = sim.spec();
    if (ctx.has_input("initial_theta")) {
        std::vector<float> d = on_grid(ctx, *ctx.input_field3d("initial_theta"), 0, s, origin, "initial_theta");
        if (ctx.get_bool("initial_is_temperature")) to_theta(d, sim);
        sim.add_theta(d);
    }
    if (ctx.has_input("initial_vapour")) {
        const std::vector<float> d = on_grid(ctx, *ctx.input_field3d("initial_vapour"), 0, s, origin, "initial_vapour");
        std::vector<float>& qv = sim.qv();
        for (size_t c = 0; c < d.size(); ++c) {
            qv[c] += d[c];
            if (qv[c] < 0)
                ctx.fail("input 'initial_vapour' makes qv = " + std::to_string(qv[c]) + " kg/kg < 0 at cell " + std::to_string(c) +
                         " (qv' is added to the sounding's vapour; water is not clamped)");
        }
    }
    if (ctx.has_input("initial_velocity")) {
        const Field3DPtr f = ctx.input_field3d("initial_velocity");
        if (f->channels() < 3) ctx.fail("input 'initial_velocity' needs 3 channels (u, v, w), got " + std::to_string(f->channels()));
        const char* names[3] = {"vel.x", "vel.y", "vel.z"};
        std::vector<float> c[3];
        for (int a = 0; a < 3; ++a) {
            const int ch = f->find_channel(names[a]);
            c[a] = on_grid(ctx, *f, ch >= 0 ? ch : a, s, origin, "initial_velocity");
        }
        sim::MacVelocity& v = sim.velocity();
        auto cell = [&](int a, int i, int j, int k) { // clamped; wrapped along a periodic axis
            i = s.periodic(0) ? (i + s.nx) % s.nx : std::clamp(i, 0, s.nx - 1);
            j = s.periodic(1) ? (j + s.ny) % s.ny : std::clamp(j, 0, s.ny - 1);
            k = std::clamp(k, 0, s.nz - 1);
            return double(c[a][v.ic(i, j, k)]);
        };
        for (int k = 0; k < s.nz; ++k)
            for (int j = 0; j < s.ny; ++j)
                for (int i = 0; i <= s.nx; ++i) v.u[v.iu(i, j, k)] = float(0.5 * (cell(0, i - 1, j, k) + cell(0, i, j, k)));
        for (int k = 0; k < s.nz; ++k)
            for (int j = 0; j <= s.ny; ++j)
                for (int i = 0; i < s.nx; ++i) v.v[v.iv(i, j, k)] = float(0.5 * (cell(1, i, j - 1, k) + cell(1, i, j, k)));
        for (int k = 0; k <= s.nz; ++k)
            for (int j = 0; j < s.ny; ++j)
                for (int i = 0; i < s.nx; ++i) v.w[v.iw(i, j, k)] = float(0.5 * (cell(2, i, j, k - 1) + cell(2, i, j, k)));
        v.enforce_walls();
    }
}

std::vector<float> bubble(const sim::GridSpec& s, const Vec3d& origin, double amp, const Vec3d& c, const Vec3d& r) {
    std::vector<float> d(s.cells(), 0.f);
    size_t n = 0;
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j < s.ny; ++j)
            for (int i = 0; i < s.nx; ++i, ++n) {
                double x = origin[0] + (i + 0.5) * s.dx - c[0], y = origin[1] + (j + 0.5) * s.dx - c[1];
                const double z = origin[2] + (k + 0.5) * s.dx - c[2];
                // Periodic axes: the nearest image of the centre (the bubble wraps).
                if (s.periodic(0)) x -= s.nx * s.dx * std::round(x / (s.nx * s.dx));
                if (s.periodic(1)) y -= s.ny * s.dx * std::round(y / (s.ny * s.dx));
                const double ex = x / r[0], ey = y / r[1], ez = z / r[2];
                const double l = std::sqrt(ex * ex + (s.ny > 1 ? ey * ey : 0.0) + ez * ez);
                if (l < 1) d[n] = float(amp * std::pow(std::cos(0.5 * M_PI * l), 2));
            }
    return d;
}

// A copy of a solver output over the node's world bounds, with new channel names.
Field3DPtr placed(const CookContext& ctx, const Field3D& f, const Box3d& box, std::vector<std::string> names) {
    auto out = ctx.make_field3d(f.resolution(), f.channels(), box, std::move(names));
    for (int c = 0; c < f.channels(); ++c) std::copy(f.channel(c).begin(), f.channel(c).end(), out->channel(c).begin());
    return out;
}

std::string step_key(int step, const char* what) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "step_%04d.%s", step, what);
    return buf;
}

// Heights (m above the grid floor) of the lowest and highest cell centres
// holding cloud (qc > threshold); -1 when there is none.
std::pair<double, double> cloud_extent(const sim::Simulation& sim, float threshold) {
    const sim::GridSpec& s = sim.spec();
    const size_t layer = size_t(s.nx) * size_t(s.ny);
    int lo = -1, hi = -1;
    for (int k = 0; k < s.nz; ++k) {
        const auto first = sim.qc().begin() + std::ptrdiff_t(size_t(k) * layer);
        if (std::any_of(first, first + std::ptrdiff_t(layer), [&](float q) { return q > threshold; })) {
            if (lo < 0) lo = k;
            hi = k;
        }
    }
    return {lo < 0 ? -1.0 : (lo + 0.5) * s.dx, hi < 0 ? -1.0 : (hi + 0.5) * s.dx};
}

constexpr float kCloudThreshold = 1e-5f; // kg/kg: a visible cloud edge

void record_step(CookContext& ctx, int step, const sim::StepReport& r, const sim::Simulation& sim) {
    const auto [base, top] = cloud_extent(sim, kCloudThreshold);
    ctx.metric(step_key(step, "cloud_base"), base);
    ctx.metric(step_key(step, "cloud_top"), top);
    ctx.metric(step_key(step, "substeps"), r.substeps);
    ctx.metric(step_key(step, "pressure_iterations"), r.pressure_iterations);
    ctx.metric(step_key(step, "div_l2"), r.divergence.l2);
    ctx.metric(step_key(step, "div_max"), r.divergence.max);
    ctx.metric(step_key(step, "step_error"), r.step_error);
    ctx.metric(step_key(step, "accuracy_dt"), r.accuracy_dt);
    ctx.metric(step_key(step, "accuracy_limited"), std::string(r.dt_limit) == "accuracy" ? 1.0 : 0.0);
    ctx.metric(step_key(step, "vapour_sink_deficit"), r.vapour_sink_deficit);
    ctx.metric(step_key(step, "water_redistributed"), r.water_redistributed);
    ctx.metric(step_key(step, "water_drift"), r.water_drift);
    ctx.metric(step_key(step, "theta_l_drift"), r.theta_l_drift);
    ctx.metric(step_key(step, "max_w"), r.max_w);
    ctx.metric(step_key(step, "max_qc"), r.max_qc);
    ctx.metric(step_key(step, "seconds_advect"), r.seconds_advect);
    ctx.metric(step_key(step, "seconds_sources"), r.seconds_sources);
    ctx.metric(step_key(step, "seconds_thermo"), r.seconds_thermo);
    ctx.metric(step_key(step, "seconds_forces"), r.seconds_forces);
    ctx.metric(step_key(step, "seconds_project"), r.seconds_project);
}

void cook(CookContext& ctx) {
    const Vec3i res = ctx.get_int3("resolution");
    sim::GridSpec spec;
    spec.nx = res[0];
    spec.ny = res[1];
    spec.nz = res[2];
    spec.dx = ctx.get_float("dx");
    const std::string& bnd = ctx.get_string("boundary");
    if (bnd == "open_top") spec.boundary[5] = sim::Boundary::Open;
    if (bnd == "open_sides_top") {
        spec.boundary = sim::all_open();
        spec.boundary[4] = sim::Boundary::Closed;
    }
    if (bnd == "open_sides") {
        spec.boundary = sim::all_open();
        spec.boundary[4] = spec.boundary[5] = sim::Boundary::Closed;
    }
    for (int a = 0; a < 2; ++a) {
        const char* name = a == 0 ? "boundary_x" : "boundary_y";
        const std::string& v = ctx.get_string(name);
        if (v == "as_boundary") continue;
        const sim::Boundary f = v == "closed" ? sim::Boundary::Closed : v == "open" ? sim::Boundary::Open : sim::Boundary::Periodic;
        spec.boundary[size_t(2 * a)] = spec.boundary[size_t(2 * a + 1)] = f;
        const int n = a == 0 ? res[0] : res[1];
        if (f == sim::Boundary::Periodic && n > 1 && n % 2 != 0)
            ctx.fail(std::string("parameter '") + name + "': periodic needs an even resolution " + (a == 0 ? "x" : "y") + ", got " +
                     std::to_string(n));
    }
    spec.validate(); // library errors: the evaluator prefixes the node
    const Vec3d origin = ctx.get_float3("origin");
    const Box3d box{origin, {{origin[0] + res[0] * spec.dx, origin[1] + res[1] * spec.dx, origin[2] + res[2] * spec.dx}}};
    if (!box.valid()) ctx.fail("origin + resolution * dx is not a valid box (too large or non-finite)");

    const double duration = ctx.get_float("duration"), frame_dt = ctx.get_float("frame_dt");
    const double nsteps_real = std::ceil(duration / frame_dt * (1 - 1e-12));
    if (!(nsteps_real <= 1e6)) ctx.fail("duration / frame_dt is " + std::to_string(nsteps_real) + " steps; at most 1e6");
    const int steps = std::max(1, int(nsteps_real));
    const int every = int(ctx.get_int("sequence_every"));
    if (every > steps)
        ctx.fail("parameter 'sequence_every' is " + std::to_string(every) + " but the run has only " + std::to_string(steps) + " step(s)");
    const int frames = every == 0 ? 1 : steps / every;
    const std::vector<std::string> grids = split_grids(ctx);
    int per_frame = 0;
    for (const auto& g : grids) per_frame += g == "vel" ? 3 : 1;

    // Everything this cook holds at its peak, checked before anything is allocated.
    const uint64_t cells = spec.cells();
    const sim::SimOptions opt = options_from(ctx, spec.nz, spec.dx);
    const uint64_t state = sim::simulation_bytes(spec, opt);
    const uint64_t outputs = field_bytes(cells, 7 + uint64_t(frames) * uint64_t(per_frame));
    ctx.check_memory(state + outputs, "the simulation (" + std::to_string(state / std::max<uint64_t>(cells, 1)) +
                                          " B per cell with these options) and its outputs");
    ctx.metric("simulation_bytes", double(state));

    // Unconnected: the sim/sounding node's defaults, so it means the same atmosphere.
    const sim::Sounding snd = ctx.has_input("sounding") ? sim_nodes::sounding_from_record(ctx, *ctx.input_field2d("sounding"), "sounding")
                                                        : sim::capped_boundary_layer_sounding();
    opt.validate(spec.nz);
    sim::Simulation sim(spec, snd, opt, &ctx.budget());
    if (ctx.has_input("emitter")) apply_emitter(ctx, sim, origin);
    if (ctx.get_float("patch_radius") > 0) {
        sim::GroundPatch g;
        const Vec2d c = ctx.get_float2("patch_center");
        g.center_x = c[0] - origin[0];
        g.center_y = c[1] - origin[1];
        g.radius = ctx.get_float("patch_radius");
        g.depth = ctx.get_float("patch_depth");
        g.heat_rate = ctx.get_float("patch_heat_rate");
        g.vapour_rate = ctx.get_float("patch_vapour_rate");
        g.noise_scale = ctx.get_float("patch_noise_scale");
        g.noise_amount = ctx.get_float("patch_noise_amount");
        g.seed = uint32_t(ctx.get_int("seed"));
        sim.add_ground_patch(g);
    }
    if (const double a = ctx.get_float("bubble_theta"); a != 0) {
        const Vec3d radii = ctx.get_float3("bubble_radii");
        const double r0 = ctx.get_float("bubble_radius");
        const bool ellipsoid = radii[0] > 0 && radii[1] > 0 && radii[2] > 0;
        std::vector<float> d = bubble(spec, origin, a, ctx.get_float3("bubble_center"), ellipsoid ? radii : Vec3d{{r0, r0, r0}});
        if (ctx.get_bool("bubble_is_temperature")) to_theta(d, sim);
        sim.add_theta(d);
    }
    apply_initial_state(ctx, sim, origin);

    std::vector<std::string> seq_names;
    for (int f = 1; f <= frames; ++f)
        for (const auto& g : grids)
            for (const std::string& c : sim::sequence_grid_channels(g)) seq_names.push_back(sim::sequence_channel_name(f, c));
    auto sequence = ctx.make_field3d(res, int(seq_names.size()), box, seq_names);
    int next_channel = 0;
    auto keep_frame = [&] {
        for (const auto& g : grids) {
            if (g == "density") {
                std::copy(sim.qc().begin(), sim.qc().end(), sequence->channel(next_channel++).begin());
            } else if (g == "vapor") {
                std::copy(sim.qv().begin(), sim.qv().end(), sequence->channel(next_channel++).begin());
            } else if (g == "temperature") {
                const Field3D t = sim.temperature();
                std::copy(t.channel(0).begin(), t.channel(0).end(), sequence->channel(next_channel++).begin());
            } else {
                const Field3D v = sim.velocity_field();
                for (int a = 0; a < 3; ++a) std::copy(v.channel(a).begin(), v.channel(a).end(), sequence->channel(next_channel++).begin());
            }
        }
    };

    double div_l2 = 0, div_max = 0, water = 0, theta_l = 0, max_w = 0, max_qc = 0, max_qr = 0, fallout = 0;
    double s_adv = 0, s_src = 0, s_thermo = 0, s_forces = 0, s_proj = 0, step_error = 0, sink_deficit = 0, redistributed = 0;
    int accuracy_limited = 0;
    int substeps = 0, iterations = 0, unconverged = 0;
    for (int step = 1; step <= steps; ++step) {
        ctx.progress(double(step - 1) / steps);
        const sim::StepReport r = sim.step(frame_dt);
        record_step(ctx, step, r, sim);
        div_l2 = std::max(div_l2, r.divergence.l2);
        div_max = std::max(div_max, r.divergence.max);
        water = std::max(water, std::fabs(r.water_drift));
        theta_l = std::max(theta_l, r.theta_l_drift);
        max_w = std::max(max_w, r.max_w);
        max_qc = std::max(max_qc, r.max_qc);
        max_qr = std::max(max_qr, r.max_qr);
        fallout += r.rain_fallout;
        step_error = std::max(step_error, r.step_error);
        sink_deficit += r.vapour_sink_deficit;
        redistributed += r.water_redistributed;
        if (std::string(r.dt_limit) == "accuracy") ++accuracy_limited;
        s_adv += r.seconds_advect;
        s_src += r.seconds_sources;
        s_thermo += r.seconds_thermo;
        s_forces += r.seconds_forces;
        s_proj += r.seconds_project;
        substeps += r.substeps;
        iterations += r.pressure_iterations;
        if (!r.pressure_converged) ++unconverged;
        if (every > 0 && step % every == 0 && step / every <= frames) keep_frame();
    }
    if (every == 0) keep_frame();
    ctx.progress(1.0);
    if (unconverged > 0)
        ctx.warn(std::to_string(unconverged) + " step(s) ended with a pressure solve that did not reach pressure_tolerance within "
                 "pressure_max_iterations");
    ctx.metric("steps", steps);
    ctx.metric("substeps", substeps);
    ctx.metric("pressure_iterations", iterations);
    ctx.metric("div_l2_max", div_l2);
    ctx.metric("div_max_max", div_max);
    ctx.metric("step_error_max", step_error);
    ctx.metric("accuracy_limited_steps", accuracy_limited);
    ctx.metric("vapour_sink_deficit", sink_deficit);
    ctx.metric("water_redistributed", redistributed);
    ctx.metric("water_drift_max", water);
    ctx.metric("theta_l_drift_max", theta_l);
    ctx.metric("max_w", max_w);
    ctx.metric("max_qc", max_qc);
    if (opt.rain) {
        ctx.metric("max_qr", max_qr);
        ctx.metric("rain_fallout_kg", fallout);
    }
    ctx.metric("seconds_advect", s_adv);
    ctx.metric("seconds_sources", s_src);
    ctx.metric("seconds_thermo", s_thermo);
    ctx.metric("seconds_forces", s_forces);
    ctx.metric("seconds_project", s_proj);
    ctx.metric("sequence_frames", frames);
    const auto [base, top] = cloud_extent(sim, kCloudThreshold);
    ctx.metric("cloud_base", base);
    ctx.metric("cloud_top", top);

    ctx.set_output("out", Field3DPtr(placed(ctx, sim.cloud_water(), box, {"density"})));
    ctx.set_output("temperature", Field3DPtr(placed(ctx, sim.temperature(), box, {"temperature"})));
    ctx.set_output("vapour", Field3DPtr(placed(ctx, sim.vapour(), box, {"vapor"})));
    ctx.set_output("velocity", Field3DPtr(placed(ctx, sim.velocity_field(), box, {"vel.x", "vel.y", "vel.z"})));
    ctx.set_output("rain", Field3DPtr(placed(ctx, sim.rain_water(), box, {"rain"})));
    ctx.set_output("sequence", Field3DPtr(std::move(sequence)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "sim/cloud_growth", .version = 3, .declare = declare, .cook = cook});
}
