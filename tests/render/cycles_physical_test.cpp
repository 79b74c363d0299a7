// The physical lighting (RenderSettings::artistic = false) that the Cycles
// reference compares against (docs/render.md, "Reference: Cycles"): checked
// here against closed forms, independently of Blender.
#include "render_scenes.h"

#include "atlas/core/error.h"
#include "atlas/render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace atlas::render {
namespace {

// Uniform density 1 in a 1 km cube (profile 1, scale 1: the sharpening power returns 1).
CloudScene uniform_box() {
    return testing::make_scene(16, 1000, [](Vec3d) { return -1000.0; }, [](Vec3d, double) { return 1.0; });
}

double hg_atlas(double c, double g) { return (1 - g * g) / std::pow(1 + g * g - 2 * g * c, 1.5); } // 4 pi x HG

RenderSettings thin_box_settings(RenderMode mode) {
    RenderSettings s;
    s.width = 9;
    s.height = 9;
    s.camera.position = {{500, -1500, 500}};
    s.camera.look_at = {{500, 500, 500}};
    s.camera.fov_deg = 2; // the central pixels all cross the box's middle
    s.sun_direction = sun_direction(0, 60);
    s.sun_colour = {{1, 1, 1}};
    s.sky_colour = {{0, 0, 0}};
    s.extinction = 1e-4; // optical depth 0.1 across the box
    s.artistic = false;
    s.ms_octaves = 0;
    s.hg_forward = 0.33;
    s.hg_forward_weight = 1;
    s.mode = mode;
    return s;
}

// Single scattering of the sun through a thin uniform box, at the central
// pixel: integral over the view ray of sigma e^(-sigma t) phase E/(4 pi)
// e^(-sigma l_sun(t)), with l_sun the path from the ray point to the box
// boundary toward the sun (exits through the top or the front face).
double analytic_centre(const RenderSettings& s) {
    const double sigma = s.extinction;
    const Vec3d sun = s.sun_direction / length(s.sun_direction);
    const double phase = hg_atlas(dot(Vec3d{{0, 1, 0}}, sun), s.hg_forward);
    const int n = 20000;
    double L = 0;
    for (int i = 0; i < n; ++i) {
        const double y = (i + 0.5) * 1000.0 / n, z = 500;
        const double l_top = (1000 - z) / sun[2], l_front = sun[1] < 0 ? y / -sun[1] : 1e300;
        L += sigma * std::exp(-sigma * y) * phase * std::exp(-sigma * std::min(l_top, l_front)) * (1000.0 / n);
    }
    return L;
}

TEST(CyclesPhysical, ThinBoxSingleScatteringMatchesTheClosedForm) {
    const CloudScene box = uniform_box();
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        const RenderSettings s = thin_box_settings(mode);
        const double expect = analytic_centre(s);
        const RenderResult r = render_clouds(box, s);
        const double got = r.image.at(1, 4, 4); // green: sun colour 1, no sky
        EXPECT_NEAR(got, expect, 0.02 * expect) << (mode == RenderMode::Fast ? "fast" : "reference");
        EXPECT_NEAR(r.image.at(3, 4, 4), std::exp(-0.1), 0.01);
        // Twice the sun colour is twice the radiance (the export's E = 4 pi x colour is linear).
        RenderSettings s2 = s;
        s2.sun_colour = {{2, 2, 2}};
        EXPECT_NEAR(render_clouds(box, s2).image.at(1, 4, 4), 2 * got, 1e-6 * got);
    }
}

TEST(CyclesPhysical, NoPowderAndTheLookDiffers) {
    // Physical mode differs from the artistic look (powder, dual lobe, profile terms)...
    const CloudScene box = uniform_box();
    RenderSettings phys = thin_box_settings(RenderMode::Fast);
    RenderSettings art = phys;
    art.artistic = true;
    EXPECT_GT(std::fabs(render_clouds(box, phys).image.at(1, 4, 4) - render_clouds(box, art).image.at(1, 4, 4)), 1e-4);
    EXPECT_TRUE(render_clouds(box, phys).report.physical);
    // ... and the octaves add light, more with more octaves, none without medium around.
    RenderSettings ms = phys;
    ms.ms_octaves = 8;
    const double single = render_clouds(box, phys).image.at(1, 4, 4), multi = render_clouds(box, ms).image.at(1, 4, 4);
    EXPECT_GT(multi, single);
    ms.extinction = 1e-9;
    phys.extinction = 1e-9;
    EXPECT_NEAR(render_clouds(box, ms).image.at(1, 4, 4), render_clouds(box, phys).image.at(1, 4, 4), 1e-9);
}

TEST(CyclesPhysical, ScatterPowerWeightsTheOctaves) {
    // The octaves are weighted by q^ms_scatter_power, q = 1 - e^-(tau_sun + tau_zenith) < 1:
    // power 0 drops the weighting (more light), a higher power gives less; the
    // default (1) is the weighting itself, and the difference to single
    // scattering scales with q^p sample by sample, so with q < 1 everywhere the
    // octave light at power 2 is below that at power 1 by at least the largest q.
    const CloudScene box = uniform_box();
    RenderSettings s = thin_box_settings(RenderMode::Fast);
    const double single = render_clouds(box, s).image.at(1, 4, 4);
    s.ms_octaves = 8;
    const double p1 = render_clouds(box, s).image.at(1, 4, 4);
    s.ms_scatter_power = 0;
    const double p0 = render_clouds(box, s).image.at(1, 4, 4);
    s.ms_scatter_power = 2;
    const double p2 = render_clouds(box, s).image.at(1, 4, 4);
    EXPECT_GT(p0, p1);
    EXPECT_GT(p1, p2);
    EXPECT_GT(p2, single);
    // Optical depth 0.1 across the box: tau_sun + tau_zenith < 0.3 at every sample, so q < 1 - e^-0.3.
    EXPECT_LT((p2 - single) / (p1 - single), 1 - std::exp(-0.3));
    RenderSettings bad = s;
    bad.ms_scatter_power = -1;
    EXPECT_THROW(render_clouds(box, bad), Error);
    bad.ms_scatter_power = 9;
    EXPECT_THROW(render_clouds(box, bad), Error);
}

TEST(CyclesPhysical, SkyIsTheSphereMeanUnderMultipleScattering) {
    // A thick uniform box under a uniform sky and no sun, albedo 1: with multiple
    // scattering the cloud is exactly as bright as the sky (the furnace test).
    const CloudScene box = uniform_box();
    RenderSettings s = thin_box_settings(RenderMode::Fast);
    s.sun_colour = {{0, 0, 0}};
    s.sky_colour = {{0.3f, 0.4f, 0.5f}};
    s.extinction = 0.01;
    s.ms_octaves = 8;
    const RenderResult r = render_clouds(box, s);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.image.at(c, 4, 4), s.sky_colour[c], 1e-3) << c;
    // A gradient: the mean over the sphere is horizon + (zenith - horizon) / 4.
    s.sky_horizon = Vec3f{{0.6f, 0.6f, 0.6f}};
    s.extinction = 1; // opaque: nothing of the background shows
    const RenderResult g = render_clouds(box, s);
    EXPECT_NEAR(g.image.at(0, 4, 4), 0.6 + (0.3 - 0.6) / 4, 2e-3);
}

TEST(CyclesPhysical, DensitySceneReproducesTheSampledDensity) {
    const CloudScene sphere = testing::sphere_scene(24, 1000, 350);
    const Field3D d = sample_density(sphere, {{24, 24, 24}});
    const Field3D back = sample_density(density_scene(d), {{24, 24, 24}});
    double worst = 0, peak = 0;
    for (size_t i = 0; i < d.channel(0).size(); ++i) {
        worst = std::max(worst, double(std::fabs(d.channel(0)[i] - back.channel(0)[i])));
        peak = std::max(peak, double(d.channel(0)[i]));
    }
    EXPECT_GT(peak, 0.5);
    EXPECT_LT(worst, 1e-5);
    EXPECT_THROW(sample_density(sphere, {{0, 4, 4}}), Error);
}

} // namespace
} // namespace atlas::render
