// Multiple scattering in optically thick media by diffusion on the light grid
// (RenderSettings::ms_diffusion; docs/render.md, "Multiple scattering by
// diffusion"), checked against closed forms: a thick conservative slab's
// reflected radiance (Chandrasekhar's H-function for isotropic scattering),
// no light without medium, thread-count independence, convergence in the
// sweep count; the octave-only model is the negative control.
#include "render_scenes.h"
#include "../../libatlas/src/render/diffusion.h" // internal: the grid the 2.5D march reads

#include "atlas/core/error.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/render/layer.h"
#include "atlas/render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

namespace atlas::render {
namespace {

// Chandrasekhar's H-function of conservative isotropic scattering (albedo 1),
// from its second form 1 / H(mu) = 1/2 int_0^1 mu' H(mu') / (mu + mu') dmu'
// (Radiative Transfer, ch. V) by damped fixed-point iteration on a midpoint grid:
// H(1) = 2.9078 in Chandrasekhar's table.
// The midpoint grid's converged values, computed once (10^8 operations).
class ChandrasekharH {
public:
    static const ChandrasekharH& get() {
        static const ChandrasekharH table;
        return table;
    }
    double operator()(double x) const {
        double acc = 0;
        for (int j = 0; j < kN; ++j) acc += m_[size_t(j)] * h_[size_t(j)] / (x + m_[size_t(j)]);
        return 1.0 / (0.5 * acc / kN);
    }

private:
    static constexpr int kN = 1000;
    std::vector<double> m_ = std::vector<double>(kN), h_ = std::vector<double>(kN, 1.0);
    ChandrasekharH() {
        for (int i = 0; i < kN; ++i) m_[size_t(i)] = (i + 0.5) / kN;
        for (int it = 0; it < 100; ++it) {
            std::vector<double> next(kN);
            // The map inverts a scale error (c H -> H / c): step to the geometric mean.
            for (int i = 0; i < kN; ++i) next[size_t(i)] = std::sqrt(h_[size_t(i)] * (*this)(m_[size_t(i)]));
            h_ = next;
        }
    }
};

double chandrasekhar_h(double mu) { return ChandrasekharH::get()(mu); }

// Chandrasekhar's reflection of a semi-infinite conservative medium
// (isotropic scattering) lit by the sky L(mu0) = mu0 (mu0 the incoming
// direction's height), seen straight down: (H(1) / 2) int_0^1 H(mu0) mu0^2 /
// (1 + mu0) dmu0 (each sky direction a beam of irradiance L dOmega; L = 1
// gives 1, the furnace). 0.679.
double chandrasekhar_sky_reflection() {
    const int n = 400;
    double acc = 0;
    for (int i = 0; i < n; ++i) {
        const double mu = (i + 0.5) / n;
        acc += chandrasekhar_h(mu) * mu * mu / (1 + mu) / n;
    }
    return 0.5 * chandrasekhar_h(1.0) * acc;
}

// A slab of uniform density 1 filling z < 800 m of a 1 km cube (64^3 voxels
// of 15.6 m): at extinction 0.064/m optical depth 51 vertically, 64 across.
CloudScene slab() {
    return testing::make_scene(64, 1000, [](Vec3d p) { return p[2] - 800.0; }, [](Vec3d, double) { return 1.0; });
}

CloudScene uniform_box() {
    return testing::make_scene(40, 1000, [](Vec3d) { return -1000.0; }, [](Vec3d, double) { return 1.0; });
}

RenderSettings physical(bool diffusion) {
    RenderSettings s;
    s.sun_colour = {{1, 1, 1}};
    s.sky_colour = {{0, 0, 0}};
    s.artistic = false;
    s.ms_octaves = kPhysicalMsOctaves;
    s.multiple_scattering = 1;
    s.ambient_strength = 1;
    s.hg_forward = 0.33;
    s.hg_forward_weight = 1;
    s.ms_diffusion = diffusion;
    return s;
}

// Looking straight down at the slab's centre, sun 60 degrees high.
RenderSettings slab_view(bool diffusion, double g) {
    RenderSettings s = physical(diffusion);
    s.width = s.height = 5;
    s.camera.position = {{500, 500, 3000}};
    s.camera.look_at = {{500, 500, 0}};
    s.camera.up = {{0, 1, 0}};
    s.camera.fov_deg = 2;
    s.sun_direction = sun_direction(0, 60);
    s.extinction = 0.064;
    s.hg_forward = g;
    return s;
}

double centre_green(const RenderResult& r) { return r.image.at(1, 2, 2); }

TEST(MsDiffusion, ThickSlabReflectsLikeChandrasekhar) {
    // Conservative semi-infinite medium, isotropic scattering: the reflected
    // radiance is (E / 4 pi) mu0 H(mu) H(mu0) / (mu + mu0), all orders
    // (Chandrasekhar, Radiative Transfer, eq. IV.(38)); E / 4 pi is the sun
    // colour (1). mu = 1 (looking down), mu0 = sin 60.
    const double mu0 = std::sin(60 * std::numbers::pi / 180);
    const double h1 = chandrasekhar_h(1.0);
    EXPECT_NEAR(h1, 2.9078, 2e-3); // the closed form's own check
    const double expect = mu0 * h1 * chandrasekhar_h(mu0) / (1 + mu0);
    const CloudScene sc = slab();
    const double diff = centre_green(render_clouds(sc, slab_view(true, 0.0)));
    const double oct = centre_green(render_clouds(sc, slab_view(false, 0.0)));
    // Optical depth 51: about 2.5% goes through (diffusion: (4/3) / (tau + 4/3)).
    EXPECT_NEAR(diff, expect, 0.12 * expect) << "diffusion " << diff << " octaves " << oct << " expect " << expect;
    // Negative control: the octaves alone give well under half of it.
    EXPECT_LT(oct, 0.5 * expect) << oct;
    // Reference mode (marched light, small steps) draws the same diffusion grid.
    RenderSettings ref = slab_view(true, 0.0);
    ref.mode = RenderMode::Reference;
    ref.reference_step = 2;
    const double diff_ref = centre_green(render_clouds(sc, ref));
    EXPECT_NEAR(diff_ref, expect, 0.15 * expect) << diff_ref;
}

TEST(MsDiffusion, ThickBlockFacesTheSkyItSees) {
    // The voxel mode's sky field, no sun: the slab of slab() is a block
    // (1 km wide, 800 m tall, optical depth 51-64) whose sides are the grid's
    // edges, so Chandrasekhar's semi-infinite value (the layer's deck test
    // below) is not its answer: light leaves through its sides and base. What
    // holds: under lerp(horizon 0.5, zenith 0.1, saturate(w . up)) its top,
    // seen from above, lies between the zenith colour and the sphere's mean
    // (0.4, the octave-only model's, the negative control) and well under
    // the mean; its base, seen from below, between the mean and the horizon
    // colour; under a uniform sky (zenith = horizon) it is exactly the sky
    // (the furnace).
    const CloudScene sc = slab();
    const double zenith = 0.1, horizon = 0.5, mean = horizon + (zenith - horizon) / 4;
    RenderSettings s = slab_view(true, 0.0);
    s.sun_colour = {{0, 0, 0}};
    s.sky_colour = {{float(zenith), float(zenith), float(zenith)}};
    s.sky_horizon = Vec3f{{float(horizon), float(horizon), float(horizon)}};
    const double top = centre_green(render_clouds(sc, s));
    EXPECT_GT(top, zenith);
    EXPECT_LT(top, 0.75 * mean) << top; // measured 0.254
    RenderSettings below = s;
    below.camera.position = {{500, 500, -2000}};
    below.camera.look_at = {{500, 500, 1000}};
    const double base = centre_green(render_clouds(sc, below));
    EXPECT_GT(base, mean + 0.02) << base;
    EXPECT_LT(base, horizon) << base;
    s.ms_diffusion = below.ms_diffusion = false;
    EXPECT_NEAR(centre_green(render_clouds(sc, s)), mean, 0.01);
    EXPECT_NEAR(centre_green(render_clouds(sc, below)), mean, 0.01);
    s.ms_diffusion = true;
    s.sky_horizon = Vec3f{{0.3f, 0.3f, 0.3f}};
    s.sky_colour = {{0.3f, 0.3f, 0.3f}};
    EXPECT_NEAR(centre_green(render_clouds(sc, s)), 0.3, 1e-3);
}

TEST(MsDiffusion, BoxAgainstBruteForce) {
    // A uniform 500 m cube (optical depth 8 and 32 across), isotropic phase,
    // against every scattering order by analog Monte Carlo: the sky basis
    // saturate(w . up) (the sky field) seen on its faces and top, and the
    // sun 25 degrees above +x seen on its lit and its shadowed face. The
    // references: /usr/bin/python3 scripts/box_mc.py bench/box_mc/box_E.json
    // --paths 400000 (standard errors under 1.3%). The sun on the top is left
    // out: the voxel mode's thin source gives 0.90 / 0.66 of it at this low
    // sun (docs/render.md, "Against brute force").
    auto cube = [](Vec3d p) { return std::max({std::fabs(p[0] - 500) - 250, std::fabs(p[1] - 500) - 250, std::fabs(p[2] - 500) - 250}); };
    const CloudScene sc = testing::make_scene(64, 1000, cube, [](Vec3d, double) { return 1.0; });
    const double e = 25 * std::numbers::pi / 180;
    struct View { Vec3d target, dir; };
    const View views[5] = {{{{250, 500, 500}}, {{1, 0, 0}}},
                           {{{250, 500, 500}}, {{std::cos(e), 0, -std::sin(e)}}},
                           {{{250, 500, 500}}, {{0.5, 0, -std::sqrt(0.75)}}},
                           {{{500, 500, 750}}, {{0, 0, -1}}},
                           {{{750, 500, 500}}, {{-std::cos(e), 0, -std::sin(e)}}}};
    struct Case { double ext; int view; double sky_basis, sun; };
    // sun < 0: not compared (the shadowed face only at 25 degrees, the lit one).
    const Case cases[] = {{0.016, 0, 0.2345, -1}, {0.016, 1, 0.2199, 0.2419}, {0.016, 2, 0.2085, -1}, {0.016, 3, 0.4717, -1}, {0.016, 4, 0.2203, 2.3078},
                          {0.064, 0, 0.2172, -1}, {0.064, 1, 0.2167, 0.0694}, {0.064, 2, 0.2176, -1}, {0.064, 3, 0.6153, -1}, {0.064, 4, 0.2160, 3.2941}};
    auto render = [&](const Case& c, bool diffusion, bool sun) {
        RenderSettings s = slab_view(diffusion, 0.0);
        s.extinction = c.ext;
        s.sun_direction = {{std::cos(e), 0, std::sin(e)}};
        s.sun_colour = sun ? Vec3f{{1, 1, 1}} : Vec3f{{0, 0, 0}};
        s.sky_colour = {{0, 0, 0}}; // zenith 0, horizon 1: the pixel is 1 - the basis's weight
        s.sky_horizon = sun ? Vec3f{{0, 0, 0}} : Vec3f{{1, 1, 1}};
        const View& v = views[c.view];
        s.camera.look_at = v.target;
        s.camera.position = v.target - v.dir * 3000.0;
        s.camera.up = c.view == 3 ? Vec3d{{0, 1, 0}} : Vec3d{{0, 0, 1}};
        s.camera.fov_deg = 0.5;
        const double px = centre_green(render_clouds(sc, s));
        return sun ? px : 1 - px;
    };
    for (const Case& c : cases) {
        const double sky = render(c, true, false);
        EXPECT_NEAR(sky, c.sky_basis, 0.05 * c.sky_basis) << "extinction " << c.ext << ", view " << c.view << ": sky basis " << sky;
        if (c.view == 3) { // the sphere's mean (1/4) the octave-only model spreads: 47-59% under
            EXPECT_LT(render(c, false, false), 0.6 * c.sky_basis);
        }
        if (c.sun > 0) {
            const double sun = render(c, true, true);
            EXPECT_NEAR(sun, c.sun, (c.view == 4 ? 0.1 : 0.15) * c.sun) << "extinction " << c.ext << ", view " << c.view << ": sun " << sun;
            if (c.view == 4) {
                EXPECT_LT(render(c, false, true), 0.6 * c.sun); // the octaves alone: 44-55% under
            }
        }
    }
}

// Chandrasekhar's reflection of a semi-infinite conservative medium under
// the sky basis L(w) = saturate(w . up) whose surface's outward normal is t
// from up, seen along the normal: (H(1) / 4 pi) int L(w) mu0 H(mu0) / (1 +
// mu0) dw over the directions the surface faces (mu0 = w . n), isotropic
// scattering. t = 0: chandrasekhar_sky_reflection().
double chandrasekhar_sloped_sky_reflection(double t) {
    const int n = 200;
    const Vec3d nz{{std::sin(t), 0, std::cos(t)}}, nx{{std::cos(t), 0, -std::sin(t)}}, ny{{0, 1, 0}};
    double acc = 0;
    for (int i = 0; i < n; ++i) {
        const double mu0 = (i + 0.5) / n, s0 = std::sqrt(1 - mu0 * mu0), h = chandrasekhar_h(mu0);
        for (int j = 0; j < 2 * n; ++j) {
            const double ph = 2 * std::numbers::pi * (j + 0.5) / (2 * n);
            const Vec3d w = nz * mu0 + nx * (s0 * std::cos(ph)) + ny * (s0 * std::sin(ph));
            acc += std::max(0.0, w[2]) * mu0 * h / (1 + mu0);
        }
    }
    const double dw = (1.0 / n) * (2 * std::numbers::pi / (2 * n));
    return chandrasekhar_h(1.0) / (4 * std::numbers::pi) * acc * dw;
}

TEST(MsDiffusion, SlopedSlabTakesTheSkyOfItsSlope) {
    // The voxel mode's sky field, no sun, on a thick slab (optical depth 32
    // under the centre) whose top is tilted 0-60 degrees, seen along its
    // normal at the centre, isotropic phase: within 10% of Chandrasekhar's
    // semi-infinite reflection of the sky basis on that slope (the grid's
    // edges let some light out: 0.91 of it on the flat slab). A staircase of
    // voxel faces takes in 15-20% less sky than the slope it stands for
    // (diffusion.cpp, Incoming::slope_factor): without the factor the slab
    // at 45 degrees was 0.83 of it. The octaves' sphere mean (1/4) is the
    // negative control.
    for (double deg : {0.0, 20.0, 30.0, 45.0, 60.0}) {
        const double t = deg * std::numbers::pi / 180;
        const Vec3d n{{std::sin(t), 0, std::cos(t)}};
        const CloudScene sc =
            testing::make_scene(64, 1000, [&](Vec3d p) { return dot(p - Vec3d{{500, 500, 500}}, n); }, [](Vec3d, double) { return 1.0; });
        RenderSettings s = slab_view(true, 0.0);
        s.sun_colour = {{0, 0, 0}};
        s.sky_colour = {{0, 0, 0}}; // zenith 0, horizon 1: the pixel is 1 - the basis's weight
        s.sky_horizon = Vec3f{{1, 1, 1}};
        s.camera.look_at = {{500, 500, 500}};
        s.camera.position = Vec3d{{500, 500, 500}} + n * 3000.0;
        s.camera.fov_deg = 0.5;
        const double expect = chandrasekhar_sloped_sky_reflection(t);
        const double basis = 1 - centre_green(render_clouds(sc, s));
        EXPECT_NEAR(basis, expect, 0.1 * expect) << deg << " degrees: " << basis << " expect " << expect;
        s.ms_diffusion = false;
        EXPECT_LT(1 - centre_green(render_clouds(sc, s)), 0.7 * expect) << deg << " degrees, octaves alone";
    }
}

TEST(MsDiffusion, TowerFlankSeesTheDeckBelowItsHorizon) {
    // The sky field with the sky other clouds hide (diffusion.cpp,
    // shed_light_source with light coming in): a 200 m tower (optical depth
    // 6.4 across) on a 1 km deck (6.4 deep), the sky basis saturate(w . up)
    // only, isotropic phase, against every scattering order by analog Monte
    // Carlo (/usr/bin/python3 scripts/box_mc.py bench/box_mc/tower_0.032.json
    // --paths 400000, standard errors 0.0005). Unoccluded, the tower's flank
    // takes 0 from below its horizon, where it sees the deck's top, which
    // reflects the sky above it: without the pass the flank near the deck is
    // 34-40% under the brute force (0.268 against 0.406 at 50 m above it);
    // with it every view is within 14% (measured +13.0, +12.0, -8.8, -7.1,
    // -6.4%; +11, +9, -9, -8, -4% before the fast march jittered its first
    // step at the volume's entry rather than after the first SDF skip: one
    // pixel's sample phase at a face 6.4 optical depths thick).
    auto box = [](Vec3d p, Vec3d lo, Vec3d hi) { return std::max({lo[0] - p[0], p[0] - hi[0], lo[1] - p[1], p[1] - hi[1], lo[2] - p[2], p[2] - hi[2]}); };
    const CloudScene sc = testing::make_scene(
        64, 1000, [&](Vec3d p) { return std::min(box(p, {{0, 0, 100}}, {{1000, 1000, 300}}), box(p, {{400, 400, 300}}, {{600, 600, 900}})); },
        [](Vec3d, double) { return 1.0; });
    auto basis = [&](Vec3d target, Vec3d dir, bool shed) {
        RenderSettings s = slab_view(true, 0.0);
        s.extinction = 0.032;
        s.sun_colour = {{0, 0, 0}};
        s.sky_colour = {{0, 0, 0}}; // zenith 0, horizon 1: the pixel is 1 - the basis's weight
        s.sky_horizon = Vec3f{{1, 1, 1}};
        s.ms_inter_cloud = shed;
        s.camera.look_at = target;
        s.camera.position = target - dir * 3000.0;
        s.camera.up = {{0, 0, 1}};
        s.camera.fov_deg = 0.5;
        return 1 - centre_green(render_clouds(sc, s));
    };
    const double r = std::sqrt(0.5);
    struct View { Vec3d target, dir; double brute_force; };
    const View views[5] = {{{{400, 500, 350}}, {{1, 0, 0}}, 0.4061},  // the flank 50 m above the deck
                           {{{400, 500, 450}}, {{1, 0, 0}}, 0.3607},  // 150 m
                           {{{400, 500, 800}}, {{1, 0, 0}}, 0.2929},  // 500 m
                           {{{350, 500, 300}}, {{r, 0, -r}}, 0.4632}, // the deck's top 50 m from the tower
                           {{{100, 500, 300}}, {{r, 0, -r}}, 0.5073}}; // 300 m
    for (const View& v : views)
        EXPECT_NEAR(basis(v.target, v.dir, true), v.brute_force, 0.14 * v.brute_force) << v.target[0] << ", " << v.target[2];
    for (int k = 0; k < 2; ++k) // the negative control: the flank near the deck without the pass
        EXPECT_LT(basis(views[k].target, views[k].dir, false), 0.75 * views[k].brute_force) << views[k].target[2];
}

TEST(MsDiffusion, LightShedByOneCloudLightsAnother) {
    // Two walls of cloud (300 m thick, 800 m tall, optical depth 19 across)
    // face each other across a 200 m gap, the sun straight overhead; the
    // camera in the gap looks at the right wall's inner face. The light the
    // left wall sheds into the gap (RenderSettings::ms_inter_cloud) makes
    // that face brighter; the right wall alone sheds nothing onto itself (its
    // faces are flat: the rays about their normals meet no medium), so there
    // the term changes the face by less than 1% (the extra sweeps of the
    // second solve).
    auto wall = [](Vec3d p, double x0, double x1) { return std::max({x0 - p[0], p[0] - x1, p[2] - 800.0}); };
    const CloudScene both = testing::make_scene(64, 1000, [&](Vec3d p) { return std::min(wall(p, 100, 400), wall(p, 600, 900)); },
                                                [](Vec3d, double) { return 1.0; });
    const CloudScene right = testing::make_scene(64, 1000, [&](Vec3d p) { return wall(p, 600, 900); }, [](Vec3d, double) { return 1.0; });
    RenderSettings s = slab_view(true, 0.33); // 5 x 5, extinction 0.064, g = 0.33; then the view into the gap
    s.camera.position = {{450, 500, 400}};
    s.camera.look_at = {{700, 500, 400}};
    s.camera.up = {{0, 0, 1}};
    s.camera.fov_deg = 5;
    s.sun_direction = sun_direction(0, 90);
    auto face = [&](const CloudScene& sc, bool shed) {
        RenderSettings t = s;
        t.ms_inter_cloud = shed;
        return centre_green(render_clouds(sc, t));
    };
    const double with = face(both, true), without = face(both, false);
    EXPECT_GT(with, 1.05 * without) << with << " vs " << without;
    const double alone_with = face(right, true), alone_without = face(right, false);
    EXPECT_NEAR(alone_with, alone_without, 0.01 * alone_without) << alone_with << " vs " << alone_without;
}

TEST(MsDiffusion, SideLitThickBoxIsBrighterThanTheOctaves) {
    // The calibration's worst case (docs/render.md): a uniform 1 km box at
    // optical thickness 16 lit from the side, where the octaves are 31-35%
    // too dark against Cycles: the diffusion term adds the light that
    // diffuses around the sun ray.
    const CloudScene box = uniform_box();
    auto mean_cloud = [&](bool diffusion) {
        RenderSettings s = physical(diffusion);
        s.width = 32;
        s.height = 18;
        s.camera = framing_camera(box.modeling->bounds(), 32.0 / 18.0);
        s.sun_direction = sun_direction(120, 35);
        s.extinction = 0.016;
        const RenderResult r = render_clouds(box, s);
        double acc = 0;
        int n = 0;
        for (int y = 0; y < 18; ++y)
            for (int x = 0; x < 32; ++x)
                if (r.image.at(3, x, y) < 0.9) acc += r.image.at(1, x, y), ++n;
        EXPECT_GT(n, 50);
        return acc / n;
    };
    const double oct = mean_cloud(false), diff = mean_cloud(true);
    EXPECT_GT(diff, 1.25 * oct) << "diffusion " << diff << " octaves " << oct;
}

TEST(MsDiffusion, NoLightWithoutMediumAndSameBytesForAnyThreadCount) {
    const CloudScene sc = slab();
    // Without medium (optical thickness per voxel far below the threshold)
    // the diffusion term adds nothing: the image is the octave model's, byte
    // for byte (the larger of the two is the octaves').
    RenderSettings a = slab_view(true, 0.33), b = slab_view(false, 0.33);
    a.extinction = b.extinction = 1e-9;
    const RenderResult ra = render_clouds(sc, a), rb = render_clouds(sc, b);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(ra.image.at(c, 2, 2), rb.image.at(c, 2, 2)) << c;
    EXPECT_TRUE(ra.report.diffusion);
    EXPECT_FALSE(rb.report.diffusion);
    // The artistic look ignores the setting.
    RenderSettings art = slab_view(true, 0.33);
    art.artistic = true;
    EXPECT_FALSE(render_clouds(sc, art).report.diffusion);
    // Same bytes on 1 and 3 threads.
    RenderSettings t1 = slab_view(true, 0.33), t3 = t1;
    t1.width = t3.width = 24;
    t1.height = t3.height = 16;
    t1.camera.fov_deg = t3.camera.fov_deg = 40;
    t1.threads = 1;
    t3.threads = 3;
    const RenderResult r1 = render_clouds(sc, t1), r3 = render_clouds(sc, t3);
    EXPECT_TRUE(atlas::render::testing::same_bytes(r1.image, r3.image));
}

TEST(MsDiffusion, ConvergedInTheSweepCount) {
    // The default sweeps (32 per level of the cascade) against 16x as many:
    // within 3% on the slab (measured 2.1%); 1 sweep per level is visibly
    // off (the control).
    const CloudScene sc = slab();
    RenderSettings s = slab_view(true, 0.33);
    const double def = centre_green(render_clouds(sc, s));
    s.ms_diffusion_sweeps = 512;
    const double conv = centre_green(render_clouds(sc, s));
    s.ms_diffusion_sweeps = 1;
    const double one = centre_green(render_clouds(sc, s));
    EXPECT_NEAR(def, conv, 0.03 * conv);
    EXPECT_GT(std::fabs(one - conv), 0.05 * conv) << one << " " << conv;
    s.ms_diffusion_sweeps = 0;
    EXPECT_THROW(render_clouds(sc, s), Error);
}

// A 2.5D stratus deck: coverage 1 and profile 1 from 1500 to 4000 m over a
// 40 km map, no noise: density 1 throughout, optical depth 160 at 0.064/m.
LayerScene deck() {
    Field2D set = ndf::make_ndf_set({{8, 8}}, Box2d{{{0, 0}}, {{40000, 40000}}}, 1500, 4000, nullptr);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) set.at(ndf::Coverage, x, y) = 1.0f;
    Field2D lut({{4, 4}}, 2, Box2d{{{0, 0}}, {{1, 1}}}, {"bottom", "top"});
    for (int c = 0; c < 2; ++c) std::fill(lut.channel(c).begin(), lut.channel(c).end(), 1.0f);
    LayerScene s;
    s.ndf = std::make_shared<const Field2D>(std::move(set));
    s.profile_lut = std::make_shared<const Field2D>(std::move(lut));
    s.haze_distance = 0;
    s.rain_absorption = 0;
    s.cloud_top_offset = 0;
    return s;
}

// The deck seen obliquely from 8 km south of its centre, 6 km up, fov 40, at
// 0.016/m (optical depth 40), g = 0.33.
RenderSettings deck_view(int w, int h) {
    RenderSettings s = slab_view(true, 0.33);
    s.width = w;
    s.height = h;
    s.camera.position = {{20000, 12000, 6000}};
    s.camera.look_at = {{20000, 20000, 2500}};
    s.camera.fov_deg = 40;
    s.extinction = 0.016;
    return s;
}

TEST(MsDiffusion, LayerDeckReflectsLikeChandrasekharAtEverySunHeight) {
    // The 2.5D mode's diffusion patch (kLayerDiffusionPatch) against the same
    // closed form as the voxel slab: looking straight down on the deck's
    // centre from 10 km, isotropic phase, the sun 25, 60 and 80 degrees
    // high. At 0.016/m the deck's optical depth is 40, 1.3 per patch voxel
    // (125 x 125 x 78 m). Measured: 1.022, 0.988, 0.973 of Chandrasekhar
    // (1.055, 0.995, 0.976 without the sub-voxel share, diffusion.h);
    // the octaves alone 0.43, 0.26, 0.23 (the negative control). At 0.064/m
    // (5.3 per voxel, the superstorm's) the near-face source (diffusion.cpp,
    // ForwardFlux::marshak) gives 0.923, 1.037, 1.014 (0.919, 1.014, 0.988
    // without the share); with the source at the voxel's centre it was 1.35,
    // 1.36, 1.30 (the bound's control).
    const LayerScene sc = deck();
    for (double el : {25.0, 60.0, 80.0}) {
        const double mu0 = std::sin(el * std::numbers::pi / 180);
        const double expect = mu0 * chandrasekhar_h(1.0) * chandrasekhar_h(mu0) / (1 + mu0);
        RenderSettings s = slab_view(true, 0.0);
        s.camera.position = {{20000, 20000, 10000}};
        s.camera.look_at = {{20000, 20000, 0}};
        s.extinction = 0.016;
        s.sun_direction = sun_direction(0, el);
        const LayerResult with = render_layer(sc, s);
        EXPECT_TRUE(with.report.diffusion);
        EXPECT_LT(with.image.at(3, 2, 2), 0.01); // the deck is opaque (the march stops at min_transmittance)
        s.ms_diffusion = false;
        const LayerResult without = render_layer(sc, s);
        EXPECT_FALSE(without.report.diffusion);
        const double diff = with.image.at(1, 2, 2), oct = without.image.at(1, 2, 2);
        EXPECT_NEAR(diff, expect, 0.1 * expect) << "sun " << el << ": diffusion " << diff << " octaves " << oct << " expect " << expect;
        EXPECT_LT(oct, 0.5 * expect) << "sun " << el << ": " << oct;
        s.ms_diffusion = true;
        s.extinction = 0.064;
        const double thick = render_layer(sc, s).image.at(1, 2, 2);
        EXPECT_NEAR(thick, expect, 0.15 * expect) << "sun " << el << ", 5.3 per voxel: " << thick << " expect " << expect;
    }
}

TEST(MsDiffusion, LayerDeckReflectsTheSkyLikeChandrasekhar) {
    // The sky field (DiffusionGrid::sky_radiance) on the 2.5D deck, no sun:
    // the sky lerp(horizon 0.5, zenith 0.1, saturate(w . up)) reflected by a
    // thick deck seen from above is horizon + (zenith - horizon) x 0.679
    // (0.228), seen from below about the horizon colour (it sees the horizon
    // colour below it and lets through little of the sky above). The sphere's
    // mean the octave-only model spreads everywhere (0.4) is the negative
    // control: 75% too bright on the top, 20% too dark at the base.
    const LayerScene sc = deck();
    const double zenith = 0.1, horizon = 0.5;
    const double top_expect = horizon + (zenith - horizon) * chandrasekhar_sky_reflection();
    RenderSettings s = slab_view(true, 0.0);
    s.camera.position = {{20000, 20000, 10000}};
    s.camera.look_at = {{20000, 20000, 0}};
    s.extinction = 0.016;
    s.sun_colour = {{0, 0, 0}};
    s.sun_direction = sun_direction(0, 60);
    s.sky_colour = {{float(zenith), float(zenith), float(zenith)}};
    s.sky_horizon = Vec3f{{float(horizon), float(horizon), float(horizon)}};
    RenderSettings below = s;
    below.camera.position = {{20000, 20000, 500}};
    below.camera.look_at = {{20000, 20000, 5000}};
    for (bool field : {true, false}) {
        s.ms_diffusion = below.ms_diffusion = field;
        const double top = render_layer(sc, s).image.at(1, 2, 2), base = render_layer(sc, below).image.at(1, 2, 2);
        if (field) {
            EXPECT_NEAR(top, top_expect, 0.1 * top_expect) << "top " << top << " expect " << top_expect;
            EXPECT_NEAR(base, horizon, 0.05 * horizon) << "base " << base;
        } else {
            EXPECT_GT(top, 1.5 * top_expect) << "the sphere's mean on the top: " << top;
            EXPECT_LT(base, 0.9 * horizon) << "the sphere's mean at the base: " << base;
        }
    }
    // Optically thin decks (total optical depth 0.05: voxels of 0.0016, where
    // the field was 7% under the mean (diffusion's incoming light taken as
    // isotropic, where this sky comes from above), and 0.015: voxels of
    // 0.0005, under the solver's kDiffusionMinTau: free space to it) see the
    // whole sky: the field's share of the image (over the ground seen through
    // the deck, its extinction-0 render) is the sphere's mean's, as with the
    // octave-only model (isotropic phase: with g != 0 the field's flux term
    // weights the sky by the phase function, which the mean does not).
    for (double ext : {2e-5, 6e-6}) {
        s.extinction = 0;
        const double ground = render_layer(sc, s).image.at(1, 2, 2);
        s.extinction = ext;
        s.ms_diffusion = true;
        const double thin_field = render_layer(sc, s).image.at(1, 2, 2) - ground;
        s.ms_diffusion = false;
        const double thin_mean = render_layer(sc, s).image.at(1, 2, 2) - ground;
        EXPECT_NEAR(thin_field, thin_mean, (ext > 1e-5 ? 0.1 : 0.01) * std::fabs(thin_mean)) << "extinction " << ext << ": " << thin_field << " vs " << thin_mean;
    }
}

TEST(MsDiffusion, LayerPatchHoldsTheCloudsReachPastTheSquare) {
    // A wall of cloud one 250 m texel wide whose texel lies just past the
    // 16 km square (x 28250-28500 m, the square's edge at 28000): its density
    // reaches 28125-28625 m, all of it outside the square. layer_reach is 2
    // texels (no curl, no skew): 500 m, and the patch grows by 4 voxels of
    // 125 m to 28500. Seen head-on from the west with the patch centred on
    // the look-at point (20000, 20000), the wall's face gets the diffusion
    // term only through that growth (before it the patch ended at 28000 and
    // the image was the octaves' alone, byte for byte).
    Field2D set = ndf::make_ndf_set({{160, 160}}, Box2d{{{0, 0}}, {{40000, 40000}}}, 1500, 4000, nullptr);
    for (int y = 0; y < 160; ++y) set.at(ndf::Coverage, 113, y) = 1.0f; // texel centre x = 28375
    LayerScene sc = deck();
    sc.ndf = std::make_shared<const Field2D>(std::move(set));
    sc.curl_amount = 0;
    EXPECT_DOUBLE_EQ(layer_reach(sc), 500.0);
    sc.curl_amount = 120;
    sc.cloud_top_offset = -300; // a skew either way reaches as far
    EXPECT_DOUBLE_EQ(layer_reach(sc), 920.0);
    sc.curl_amount = 0;
    sc.cloud_top_offset = 0;
    RenderSettings s = slab_view(true, 0.33);
    s.width = s.height = 5;
    s.camera.position = {{10000, 20000, 2750}};
    s.camera.look_at = {{20000, 20000, 2750}};
    s.camera.up = {{0, 0, 1}};
    s.camera.fov_deg = 4;
    const LayerResult with = render_layer(sc, s);
    s.ms_diffusion = false;
    const LayerResult without = render_layer(sc, s);
    ASSERT_TRUE(with.report.diffusion);
    const double a = with.image.at(1, 2, 2), b = without.image.at(1, 2, 2);
    EXPECT_LT(with.image.at(3, 2, 2), 0.5) << "the centre pixel sees the wall";
    // 1.8% since the march's first step after the search ends near the
    // wall's face (bench/grain.sh): the face's first mean free path, where
    // the two terms differ least, weighs more.
    EXPECT_GT(std::fabs(a - b), 0.01 * b) << a << " vs " << b;
}

TEST(MsDiffusion, LayerPatchSameBytesForAnyThreadCountAndOnlyInThePhysicalMode) {
    const LayerScene sc = deck();
    RenderSettings s = deck_view(24, 16);
    s.threads = 1;
    const LayerResult t1 = render_layer(sc, s);
    s.threads = 3;
    const LayerResult t3 = render_layer(sc, s);
    EXPECT_TRUE(t1.report.diffusion);
    EXPECT_TRUE(atlas::render::testing::same_bytes(t1.image, t3.image));
    const auto f = t1.report.active_features();
    EXPECT_NE(std::find(f.begin(), f.end(), "ms_diffusion"), f.end());
    // A patch past the voxel cap is refused before it is allocated, naming
    // the grid (1280 x 1280 x 162 here: levels of 15.6 m over 2.5 km; the
    // deck's coarse texels reach past the square's 2 km cap, so 128 columns
    // of the square's 15.6 m are added on each side).
    RenderSettings big = s;
    big.light_grid = {{1024, 1024, 32}};
    try {
        render_layer(sc, big);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("1280 x 1280 x 162 voxels"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--light-grid"), std::string::npos) << e.what();
    }
    // The artistic look ignores the setting.
    s.artistic = true;
    EXPECT_FALSE(render_layer(sc, s).report.diffusion);
}

TEST(MsDiffusion, LayerSunUnderTheHorizonLightsNothing) {
    // The sun 10 degrees under the horizon: the Earth hides it from every
    // cloud (sun depth infinite; in the physical mode no diffusion patch
    // either), so the image is the one without a sun, byte for byte, with the
    // artistic terms on and off. Before, the physical march to the shell's top
    // and the flattened patch lit the deck from below, and the look's cone
    // lit it as if the Earth were not there.
    for (bool artistic : {false, true}) {
        const LayerScene sc = deck();
        RenderSettings s = deck_view(16, 9);
        s.artistic = artistic;
        s.sky_colour = {{0.1f, 0.2f, 0.5f}};
        s.sun_direction = sun_direction(30, -10);
        const LayerResult below = render_layer(sc, s);
        EXPECT_FALSE(below.report.diffusion);
        s.sun_colour = {{0, 0, 0}};
        const LayerResult dark = render_layer(sc, s);
        EXPECT_TRUE(atlas::render::testing::same_bytes(below.image, dark.image)) << "artistic " << artistic;
        for (int c = 0; c < below.image.channels(); ++c)
            for (float v : below.image.channel(c)) ASSERT_TRUE(std::isfinite(v)) << "artistic " << artistic;
        // The control: the same sun 10 degrees up lights the deck.
        s.sun_colour = {{1, 1, 1}};
        s.sun_direction = sun_direction(30, 10);
        const LayerResult above = render_layer(sc, s);
        EXPECT_EQ(above.report.diffusion, !artistic);
        EXPECT_GT(above.image.at(1, 8, 4), dark.image.at(1, 8, 4) + 0.1) << "artistic " << artistic;
    }
}


// DiffusionGrid::mean_sun_transmittance, which the 2.5D march compares with the sun's
// transmittance it marches (diffusion.h, kSubgridSunShare), is the mean of T over a
// voxel: on a uniform slab lit from straight above, at a voxel's centre d below the top,
// e^(-sigma d) sinh(x) / x with x = sigma h / 2 (the mean of e^-tau over the voxel's
// depth range); -1 outside the medium; and the factor the march applies stays within
// [1 - share, 1 + share (cap - 1)].
TEST(MsDiffusion, MeanSunTransmittanceIsTheVoxelMean) {
    const double ext = 0.01, h = 125;
    const Box3d box{{{0, 0, 0}}, {{1000, 1000, 1500}}};
    const detail::LightGrid grid(box, {{8, 8, 12}}, {{0, 0, 1}}, [](double, double, double z) { return z < 1000 ? 1.0f : 0.0f; });
    const detail::DiffusionGrid diff(grid, ext, 0.0, 8, detail::DiffusionGrid::Voxels::Thick);
    const double x = 0.5 * ext * h;
    for (int k = 2; k <= 6; ++k) {
        const double zc = (k + 0.5) * h, expect = std::exp(-ext * (1000 - zc)) * std::sinh(x) / x;
        // 5%: the light grid's marched sun depths are within ~0.05 of sigma d (measured
        // 3.4-4.4% off in T at these five voxels, alternating in sign).
        EXPECT_NEAR(diff.mean_sun_transmittance(500 - h / 2, 500 - h / 2, zc), expect, 0.05 * expect) << "voxel " << k;
    }
    EXPECT_EQ(diff.mean_sun_transmittance(500, 500, 1400), -1.0); // every corner above the slab
    for (double r : {0.0, 0.2, 1.0, 3.0, 1e6}) {
        const double f = detail::subgrid_sun_factor(r, 1.0);
        EXPECT_GE(f, 1 - detail::kSubgridSunShare);
        EXPECT_LE(f, 1 + detail::kSubgridSunShare * (detail::kSubgridSunCap - 1));
    }
    EXPECT_DOUBLE_EQ(detail::subgrid_sun_factor(0.3, 0.3), 1.0); // T at its mean: the grid's value
}

// A thick medium's face turned from the sun, lit only by the light diffusing through
// it: a wall x < X, z < 1000 m at the renderer's defaults (extinction 0.04/m, phase mean
// cosine 0.33: 5 optical depths per 125 m voxel, as in the superstorm), lit from above and
// from -x, its +x face moved across the lattice in steps of a fifth of a voxel. The
// diffuse light a view ray meets just inside the face (radiances' sun weight toward +x)
// came from where the lattice fell: the face sat at the voxel face past the last node
// inside (largest / smallest over the five walls 7.2, the negative control); with the
// surfaces inside the voxels (shadowed_face_surfaces) 1.3. The surface shares are the
// wall's, and the leak through the faces still balances the source.
TEST(MsDiffusion, ShadowedFaceFollowsTheSurfaceNotTheLattice) {
    const double ext = 0.04, g = 0.33, h = 125;
    const Box3d box{{{0, 0, 0}}, {{2000, 500, 1500}}};
    const Vec3d sun{{-0.5, 0.0, 0.866}}; // toward the sun: the +x faces are turned from it
    auto spread = [&](bool with_surfaces) {
        double lo = 1e30, hi = 0;
        for (int k = 0; k < 5; ++k) {
            const double wall = 1000 + (0.05 + 0.2 * k) * h;
            const detail::LightGrid::DensityFn density = [wall](double x, double, double z) { return x < wall && z < 1000 ? 1.0f : 0.0f; };
            const detail::LightGrid grid(box, {{16, 4, 12}}, sun, density);
            const std::vector<uint8_t> surfaces = detail::shadowed_face_surfaces(grid, ext, density);
            const detail::DiffusionGrid diff(grid, ext, g, 16, detail::DiffusionGrid::Voxels::Thick, true, false, false,
                                             with_surfaces ? surfaces : std::vector<uint8_t>{});
            if (with_surfaces) {
                EXPECT_NEAR(diff.total_outflow(), diff.total_source(), 0.05 * diff.total_source()) << "wall at " << wall;
                // The face turned from the sun (+x) of the last voxel inside: the wall's share of
                // the voxel past the node; a face toward the sun keeps 0.5.
                const int last = int(std::floor(wall / h - 0.5)); // the last node inside
                const size_t i = (size_t(5) * 4 + 2) * 16 + size_t(last);
                EXPECT_NEAR(surfaces[6 * i + 1] / double(detail::kSurfaceUnits), (wall - (last + 0.5) * h) / h, 1.0 / 64) << "wall at " << wall; // bisected
                const size_t top = (size_t(7) * 4 + 2) * 16 + 3; // a top voxel: its +z face is toward the sun
                EXPECT_EQ(surfaces[6 * top + 5], detail::kSurfaceUnits / 2);
            }
            double sw = 0, sky = 0;
            diff.radiances(wall - 1, 250, 500, {{1, 0, 0}}, sw, sky);
            EXPECT_TRUE(std::isfinite(sw) && sw >= 0) << sw;
            lo = std::min(lo, sw);
            hi = std::max(hi, sw);
        }
        return hi / lo;
    };
    const double with = spread(true), without = spread(false);
    std::printf("shadowed face's diffuse light over five wall positions, max / min: %.3f with the surfaces, %.3f at the lattice's faces\n", with,
                without);
    EXPECT_LT(with, 1.5);   // measured 1.32
    EXPECT_GT(without, 4.0); // measured 7.2
}

} // namespace
} // namespace atlas::render
