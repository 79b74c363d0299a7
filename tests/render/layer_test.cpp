// The 2.5D layer renderer (atlas/render/layer.h): shell geometry against
// closed forms, the curved horizon, errors, determinism, envelope skipping.
#include "atlas/core/error.h"
#include "atlas/ndf/cone_map.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/superstorm.h"
#include "atlas/ndf/vertical_profile.h"
#include "atlas/noise/recipes.h"
#include "atlas/render/layer.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

using namespace atlas;
using namespace atlas::render;

namespace {

constexpr double kR = 6360e3;

const noise::HzdNoise& small_noise() {
    static const noise::HzdNoise n = noise::make_hzd_noise(32, 16, 32, 3);
    return n;
}

// A 20 km map, clouds 1500..4000 m, uniform coverage and type.
LayerScene scene_with(double coverage, bool with_noise = true, double type = 0.66) {
    Field2D set = ndf::make_ndf_set({{16, 16}}, Box2d{{{0, 0}}, {{20000, 20000}}}, 1500, 4000, nullptr);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            set.at(ndf::Coverage, x, y) = float(coverage);
            set.at(ndf::Type, x, y) = float(type);
            set.at(ndf::TopType, x, y) = float(type);
            set.at(ndf::BottomType, x, y) = float(type);
        }
    LayerScene s;
    s.ndf = std::make_shared<const Field2D>(std::move(set));
    s.profile_lut = std::make_shared<const Field2D>(ndf::build_profile_lut(ndf::VerticalProfile{}, 16, 32, nullptr));
    if (with_noise) {
        const auto& n = small_noise();
        s.base_noise = std::make_shared<const Field3D>(n.low);
        s.detail_noise = std::make_shared<const Field3D>(n.high);
        s.curl = std::make_shared<const Field2D>(n.curl);
    }
    return s;
}

RenderSettings small_settings(int w = 64, int h = 36) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.sky_colour = {{0.2f, 0.35f, 0.8f}};
    s.sky_horizon = Vec3f{{0.6f, 0.7f, 0.85f}};
    s.sun_direction = sun_direction(150, 30);
    return s;
}

using atlas::render::testing::same_bytes;

// Points given as (x, y, altitude) over scene_with's 20 km map: |p - C| - R
// = z at the map centre only, so place them on the sphere, radial from the
// Earth's centre.
void place_at_altitude(std::vector<Vec3d>& pts) {
    const Vec3d C{{10000, 10000, -kR}};
    for (Vec3d& p : pts) {
        const double h = p[2];
        Vec3d d{{p[0] - C[0], p[1] - C[1], 0 - C[2]}};
        const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; ++a) p[a] = C[a] + d[a] / n * (kR + h);
    }
}

} // namespace

TEST(LayerGeometry, HorizontalRayFromTheGroundMeetsTheShellWhereTheClosedFormSays) {
    // From the ground at the map centre, a horizontal ray enters the cloud
    // base at sqrt((R + b)^2 - R^2) and leaves the top at sqrt((R + t)^2 - R^2).
    const Vec3d c{{0, 0, -kR}};
    double seg[4];
    const int n = shell_segments(Vec3d{{0, 0, 0}}, Vec3d{{1, 0, 0}}, c, kR, kR + 1500, kR + 4000, seg);
    ASSERT_EQ(n, 1);
    const long double R = kR;
    const double enter = double(std::sqrt((R + 1500) * (R + 1500) - R * R));
    const double leave = double(std::sqrt((R + 4000) * (R + 4000) - R * R));
    EXPECT_NEAR(seg[0], enter, 1e-6 * enter);
    EXPECT_NEAR(seg[1], leave, 1e-6 * leave);
    // Straight up: exactly the heights.
    ASSERT_EQ(shell_segments(Vec3d{{0, 0, 0}}, Vec3d{{0, 0, 1}}, c, kR, kR + 1500, kR + 4000, seg), 1);
    EXPECT_NEAR(seg[0], 1500, 1e-6);
    EXPECT_NEAR(seg[1], 4000, 1e-6);
}

TEST(LayerGeometry, RaysFromAboveCrossTheShellTwiceOrStopAtTheGround) {
    const Vec3d c{{0, 0, -kR}};
    double seg[4];
    // Straight down from 10 km: one segment 6000..8500 m, then the ground.
    ASSERT_EQ(shell_segments(Vec3d{{0, 0, 10000}}, Vec3d{{0, 0, -1}}, c, kR, kR + 1500, kR + 4000, seg), 1);
    EXPECT_NEAR(seg[0], 6000, 1e-6);
    EXPECT_NEAR(seg[1], 8500, 1e-6);
    // Horizontal from 3 km (inside the layer): it leaves the top only
    // (the base sphere is below it everywhere along the ray).
    ASSERT_EQ(shell_segments(Vec3d{{0, 0, 3000}}, Vec3d{{1, 0, 0}}, c, kR, kR + 1500, kR + 4000, seg), 1);
    EXPECT_EQ(seg[0], 0);
    EXPECT_NEAR(seg[1], std::sqrt((kR + 4000.0) * (kR + 4000.0) - (kR + 3000.0) * (kR + 3000.0)), 1e-3);
}

TEST(LayerGeometry, TwoSegmentsAroundTheInnerSphere) {
    const Vec3d c{{0, 0, -kR}};
    double seg[4];
    // From 20 km, aim at tangent height 1000 m with the base at 1500 m and the
    // ground 100 m below the tangent: the ray enters, crosses the base sphere,
    // leaves it, and crosses the shell again.
    const double rc = kR + 20000, rt = kR + 1000;
    const double a = std::acos(rt / rc);
    const Vec3d d{{std::cos(a), 0, -std::sin(a)}};
    const int n = shell_segments(Vec3d{{0, 0, 20000}}, d, c, kR + 900, kR + 1500, kR + 4000, seg);
    ASSERT_EQ(n, 2);
    const double half = std::sqrt(rc * rc - rt * rt);
    EXPECT_LT(seg[1], half);
    EXPECT_GT(seg[2], half);
    EXPECT_NEAR(seg[1] + seg[2], 2 * half, 1e-3); // symmetric about the tangent point
    EXPECT_NEAR(seg[0] + seg[3], 2 * half, 1e-3);
}

TEST(LayerRender, EmptyLayerShowsSkyAboveAndGroundBelowTheCurvedHorizon) {
    // Camera 1000 km up looking horizontally: the horizon dips by
    // acos(R / (R + a)) = 30.2 degrees. Rows above show the sky gradient
    // (T = 1), rows below the ground.
    LayerScene s = scene_with(0.0, false);
    s.haze_distance = 0;
    RenderSettings st = small_settings(8, 90);
    st.camera.fov_deg = 90;
    st.camera.position = {{10000, 10000, 1e6}};
    st.camera.look_at = {{10000, 20000, 1e6}};
    const LayerResult r = render_layer(s, st, nullptr);
    const double dip = std::acos(kR / (kR + 1e6)) * 180 / std::numbers::pi;
    const double half = std::tan(45 * std::numbers::pi / 180);
    const double u = (2 * 4.5 / 8 - 1) * half * 8 / 90.0;
    int sky_rows = 0;
    for (int y = 0; y < 90; ++y) {
        const double v = (2 * (y + 0.5) / 90 - 1) * half;
        const double elev = std::atan(v / std::sqrt(1 + u * u)) * 180 / std::numbers::pi;
        EXPECT_EQ(r.image.at(3, 4, y), 1.0f);
        const bool sky = r.image.at(2, 4, y) > 0.5f; // sky blue >= 0.8, lit ground < 0.25
        sky_rows += sky;
        if (elev > -dip + 1.0) { EXPECT_TRUE(sky) << "row " << y << " elevation " << elev; }
        if (elev < -dip - 1.0) { EXPECT_FALSE(sky) << "row " << y << " elevation " << elev; }
    }
    EXPECT_GT(sky_rows, 45) << "the horizon is below the image centre";
}

TEST(LayerRender, CameraUnderTheGroundIsAClearError) {
    LayerScene s = scene_with(0.5, false);
    RenderSettings st = small_settings();
    st.camera.position = {{10000, 10000, -5}};
    st.camera.look_at = {{10000, 20000, -5}};
    try {
        render_layer(s, st, nullptr);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("under the ground"), std::string::npos) << e.what();
    }
}

TEST(LayerRender, NonFiniteChannelIsNamed) {
    LayerScene s = scene_with(0.5, false);
    Field2D bad = *s.ndf;
    bad.at(ndf::Coverage, 3, 4) = std::nanf("");
    s.ndf = std::make_shared<const Field2D>(std::move(bad));
    try {
        validate_layer_scene(s);
        FAIL();
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("'coverage'"), std::string::npos) << m;
        EXPECT_NE(m.find("NaN"), std::string::npos) << m;
        EXPECT_NE(m.find("(3, 4)"), std::string::npos) << m;
    }
}

// The scan is a bit test on the exponent: -Inf in the very last texel is
// found, the largest and the subnormal floats are not mistaken for it.
TEST(LayerRender, NonFiniteScanSeesLastTexelAndKeepsExtremeFinites) {
    LayerScene s = scene_with(0.5, false);
    Field2D extreme = *s.ndf;
    const int w = extreme.width(), h = extreme.height();
    extreme.at(ndf::Coverage, 0, 0) = std::numeric_limits<float>::max();
    extreme.at(ndf::Coverage, 1, 0) = -std::numeric_limits<float>::max();
    extreme.at(ndf::Coverage, 2, 0) = std::numeric_limits<float>::denorm_min();
    s.ndf = std::make_shared<const Field2D>(extreme);
    EXPECT_NO_THROW(validate_layer_scene(s));
    const int last = extreme.channels() - 1;
    extreme.at(last, w - 1, h - 1) = -std::numeric_limits<float>::infinity();
    s.ndf = std::make_shared<const Field2D>(std::move(extreme));
    try {
        validate_layer_scene(s);
        FAIL() << "-Inf in the last texel was not found";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("Inf"), std::string::npos) << m;
        EXPECT_NE(m.find("(" + std::to_string(w - 1) + ", " + std::to_string(h - 1) + ")"), std::string::npos) << m;
    }
}

TEST(LayerRender, SameBytesForAnyThreadCount) {
    LayerScene s = scene_with(0.7);
    RenderSettings st = small_settings(37, 29); // not a tile multiple
    st.camera = layer_camera(s, LayerView::Ground, 37.0 / 29);
    st.threads = 1;
    const LayerResult a = render_layer(s, st, nullptr);
    st.threads = 2;
    const LayerResult b = render_layer(s, st, nullptr);
    EXPECT_TRUE(same_bytes(a.image, b.image));
    EXPECT_EQ(a.report.full_samples, b.report.full_samples);
    EXPECT_GT(a.report.full_samples, 0u);
}

TEST(LayerRender, CloudsAppearFiniteAndLitTopsAreBrighterThanBases) {
    // Overcast-ish layer, sun high: seen from above the tops are brighter than
    // the bases seen from below (Beer shadowing through the layer).
    LayerScene s = scene_with(0.9);
    RenderSettings st = small_settings(48, 27);
    st.sun_direction = sun_direction(0, 70);
    st.camera.position = {{10000, 10000, 2}};
    st.camera.look_at = {{10000, 10000, 1000}};
    st.camera.up = {{0, 1, 0}};
    const LayerResult below = render_layer(s, st, nullptr);
    st.camera.position = {{10000, 10000, 6000}};
    st.camera.look_at = {{10000, 10000, 0}};
    const LayerResult above = render_layer(s, st, nullptr);
    double lb = 0, la = 0, tb = 0;
    int n = 0;
    for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x) {
            for (int c = 0; c < 4; ++c) {
                EXPECT_TRUE(std::isfinite(below.image.at(c, x, y)));
                EXPECT_GE(below.image.at(c, x, y), 0.0f);
                EXPECT_TRUE(std::isfinite(above.image.at(c, x, y)));
            }
            lb += below.image.at(1, x, y);
            la += above.image.at(1, x, y);
            tb += below.image.at(3, x, y);
            ++n;
        }
    EXPECT_LT(tb / n, 0.9) << "clouds overhead";
    EXPECT_GT(la / n, lb / n) << "lit tops brighter than shadowed bases";
    for (const char* f : {"curved_earth", "base_noise", "detail_erosion", "curl_distortion", "cheap_search", "beer_powder", "dual_hg"}) {
        const auto v = below.report.active_features();
        EXPECT_NE(std::find(v.begin(), v.end(), f), v.end()) << f;
    }
}

TEST(LayerRender, WindTimeMovesTheClouds) {
    LayerScene s = scene_with(0.6);
    RenderSettings st = small_settings(32, 18);
    st.camera = layer_camera(s, LayerView::Ground, 32.0 / 18);
    const LayerResult a = render_layer(s, st, nullptr);
    s.time = 600;
    const LayerResult b = render_layer(s, st, nullptr);
    const LayerResult c = render_layer(s, st, nullptr);
    EXPECT_FALSE(same_bytes(a.image, b.image));
    EXPECT_TRUE(same_bytes(b.image, c.image));
}

TEST(LayerRender, ConeMapSkippingMatchesPlainMarching) {
    // Clouds only in a disc: the cone map over the tops lets the march jump
    // over the clear ring; the picture must not change beyond jitter-level noise.
    LayerScene s = scene_with(0.0);
    Field2D set = *s.ndf;
    Field2D heights({{16, 16}}, 1, set.bounds(), {"h"});
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const double r = std::hypot(x - 7.5, y - 7.5);
            const float cov = r < 4 ? 0.9f : 0.0f;
            set.at(ndf::Coverage, x, y) = cov;
            heights.at(0, x, y) = cov > 0 ? 4000.0f : 0.0f;
        }
    s.ndf = std::make_shared<const Field2D>(set);
    s.edge = MapEdge::Empty;
    ndf::ConeMapOptions o;
    o.texel_size = 20000.0 / 16;
    o.robust = true;
    RenderSettings st = small_settings(48, 27);
    st.camera.position = {{10000, -6000, 6000}};
    st.camera.look_at = {{10000, 10000, 2500}};
    const LayerResult plain = render_layer(s, st, nullptr);
    s.envelope.cone_map = std::make_shared<const Field2D>(ndf::cone_map(heights, 0, o, nullptr));
    const LayerResult fast = render_layer(s, st, nullptr);
    EXPECT_GT(fast.report.skipped_steps, 0u);
    EXPECT_LT(fast.report.cheap_samples, plain.report.cheap_samples);
    double se = 0, worst = 0;
    int n = 0;
    for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x) {
            const double d = double(fast.image.at(3, x, y)) - plain.image.at(3, x, y);
            se += d * d;
            worst = std::max(worst, std::fabs(d));
            ++n;
        }
    // The step-placement noise of plain marching itself: quality 1 vs 4.
    RenderSettings fine = st;
    fine.quality = 4;
    s.envelope.cone_map = nullptr;
    const LayerResult ref = render_layer(s, fine, nullptr);
    double se_ref = 0, worst_ref = 0, se_fast = 0, worst_fast = 0;
    for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x) {
            const double a = double(plain.image.at(3, x, y)) - ref.image.at(3, x, y);
            const double b = double(fast.image.at(3, x, y)) - ref.image.at(3, x, y);
            se_ref += a * a, worst_ref = std::max(worst_ref, std::fabs(a));
            se_fast += b * b, worst_fast = std::max(worst_fast, std::fabs(b));
        }
    // Stated tolerance (docs/render.md): against the quality-4 reference the
    // skipping march is within 1.5x (+0.002) of plain marching's RMSE and
    // 0.05 of its worst pixel, differs from plain by RMSE < 0.01, and no pixel
    // the reference sees as cloudy (T < 0.9) comes out clear (T > 0.999).
    EXPECT_LT(std::sqrt(se / n), 0.01);
    EXPECT_LT(std::sqrt(se_fast / n), 1.5 * std::sqrt(se_ref / n) + 0.002);
    EXPECT_LT(worst_fast, worst_ref + 0.05);
    for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x)
            if (ref.image.at(3, x, y) < 0.9f) { EXPECT_LT(fast.image.at(3, x, y), 0.999f) << x << "," << y; }
}

TEST(LayerAnvil, AnvilMapIsTheStencilsFalloffAndChainsByMax) {
    Field2D set = ndf::make_ndf_set({{32, 32}}, Box2d{{{0, 0}}, {{32000, 32000}}}, 1500, 4000, nullptr);
    ndf::SuperstormStencil a;
    a.center = {{16000, 16000}};
    a.radius = 8000;
    a.core = 0.25;
    a.blend = 0.5;
    a.anvil = 0.8;
    const Field2D first = ndf::superstorm_anvil(set, a, nullptr, nullptr);
    ndf::SuperstormStencil b = a;
    b.center = {{6000, 6000}};
    b.radius = 4000;
    b.blend = 1;
    b.anvil = 0.3;
    const Field2D both = ndf::superstorm_anvil(set, b, &first, nullptr);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            const double ra = length(set.texel_center(x, y) - a.center), rb = length(set.texel_center(x, y) - b.center);
            const double ga = ra < a.radius ? 1 - ndf::smoothstep(a.core * a.radius, a.radius, ra) : 0.0;
            const double gb = rb < b.radius ? 1 - ndf::smoothstep(b.core * b.radius, b.radius, rb) : 0.0;
            EXPECT_NEAR(first.at(0, x, y), a.anvil * a.blend * ga, 1e-6);
            EXPECT_NEAR(both.at(0, x, y), std::max(a.anvil * a.blend * ga, b.anvil * b.blend * gb), 1e-6);
            // The lift channel: anvil_lift x the stencil's bias, chained by max.
            EXPECT_NEAR(first.at(1, x, y), a.anvil_lift * a.anvil * a.blend * ga, 1e-3);
            EXPECT_NEAR(both.at(1, x, y), std::max(a.anvil_lift * a.anvil * a.blend * ga, b.anvil_lift * b.anvil * b.blend * gb), 1e-3);
            if (rb >= b.radius) {
                EXPECT_EQ(both.at(0, x, y), first.at(0, x, y)); // beyond the radius: the previous value exactly
            }
        }
    Field2D small({{4, 4}}, 1, set.bounds());
    EXPECT_THROW(ndf::superstorm_anvil(set, a, &small, nullptr), Error);
    a.anvil = 1.5;
    EXPECT_THROW(ndf::superstorm_anvil(set, a, nullptr, nullptr), Error);
}

TEST(LayerAnvil, AnvilBiasSpreadsTheTopsSeenFromAbove) {
    // Looking straight down on a layer of cumulonimbus at coverage 0.4: the
    // anvil bias raises the coverage in the top of every column, so the tops
    // hide more of the ground (lower mean transmittance), and only there.
    LayerScene s = scene_with(0.4, true, 1.0);
    RenderSettings st = small_settings(48, 27);
    st.camera.position = {{10000, 10000, 9000}};
    st.camera.look_at = {{10000, 10000, 0}};
    st.camera.up = {{0, 1, 0}};
    const LayerResult plain = render_layer(s, st, nullptr);
    Field2D bias({{4, 4}}, 1, s.ndf->bounds(), {"anvil_bias"});
    for (float& v : bias.channel(0)) v = 1.0f;
    s.anvil = std::make_shared<const Field2D>(std::move(bias));
    const LayerResult spread = render_layer(s, st, nullptr);
    double tp = 0, ta = 0;
    for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x) tp += plain.image.at(3, x, y), ta += spread.image.at(3, x, y);
    EXPECT_LT(ta, tp * 0.97);
    const auto f = spread.report.active_features();
    EXPECT_NE(std::find(f.begin(), f.end(), "anvil"), f.end());
    // An all-zero anvil map is no anvil: same bytes.
    Field2D zero({{4, 4}}, 1, s.ndf->bounds(), {"anvil_bias"});
    s.anvil = std::make_shared<const Field2D>(std::move(zero));
    EXPECT_TRUE(same_bytes(render_layer(s, st, nullptr).image, plain.image));
}

TEST(LayerLights, FlashesBrightenTheLayerNeverItsTransmittance) {
    LayerScene s = scene_with(0.8);
    RenderSettings st = small_settings(48, 27);
    st.camera = layer_camera(s, LayerView::Ground, 48.0 / 27);
    st.sun_colour = {{0.05f, 0.05f, 0.05f}};
    const LayerResult dark = render_layer(s, st, nullptr);
    // Flashes placed by a 2D probability map (a disc in the map's centre).
    Field2D prob({{16, 16}}, 1, s.ndf->bounds(), {"p"});
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) prob.at(0, x, y) = std::hypot(x - 7.5, y - 7.5) < 5 ? 1.0f : 0.0f;
    LightField f;
    f.probability = layer_flash_probability(prob, 0, 2000, 3000);
    f.count = 4;
    f.intensity = 5e7;
    f.radius = 8000;
    st.light_fields.push_back(f);
    const LayerResult lit = render_layer(s, st, nullptr);
    EXPECT_EQ(lit.report.point_lights, 4);
    bool brighter = false;
    for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x) {
            EXPECT_EQ(lit.image.at(3, x, y), dark.image.at(3, x, y)); // lights never change transmittance
            for (int c = 0; c < 3; ++c) {
                EXPECT_GE(lit.image.at(c, x, y), dark.image.at(c, x, y));
                EXPECT_TRUE(std::isfinite(lit.image.at(c, x, y)));
            }
            brighter = brighter || lit.image.at(1, x, y) > dark.image.at(1, x, y) * 1.5f;
        }
    EXPECT_TRUE(brighter);
    // Every flash lies over the disc, inside the height range.
    for (const PointLight& l : flash_lights(f)) {
        EXPECT_GE(l.position[2], 2000);
        EXPECT_LE(l.position[2], 3000);
        const double tx = l.position[0] / 1250.0 - 0.5, ty = l.position[1] / 1250.0 - 0.5; // texel coordinates
        EXPECT_LT(std::hypot(std::round(tx) - 7.5, std::round(ty) - 7.5), 5.8);
    }
    EXPECT_THROW(layer_flash_probability(prob, 1, 0, 1), Error);
    EXPECT_THROW(layer_flash_probability(prob, 0, 5, 5), Error);
}

TEST(LayerVortex, RingsTurnTheNoiseNotTheMapAndAFullTurnIsTheStart) {
    // One ring over the whole map turning at w rad/s, no wind: at time t the
    // noise is read turned by w t about the centre, so w t = 2 pi gives the
    // t = 0 picture (to float rounding of the rotation) and pi does not. The map
    // does not turn (000 turns the noise's sample positions): the clear east
    // half (coverage 0) stays clear at every turn.
    LayerScene s = scene_with(0.0);
    Field2D set = *s.ndf;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) set.at(ndf::Coverage, x, y) = x < 8 ? 0.9f : 0.0f; // not rotation-symmetric
    s.ndf = std::make_shared<const Field2D>(std::move(set));
    s.wind = {{0, 0}};
    s.cloud_top_offset = 0;
    Field2D table({{1, 1}}, 5, Box2d{{{0, 0}}, {{20000, 20000}}}, {"inner", "outer", "speed", "skew", "overlap_end"});
    table.at(0, 0, 0) = 0;
    table.at(1, 0, 0) = 5e5; // every visible point (the map wraps)
    table.at(2, 0, 0) = 0.01f;
    table.at(4, 0, 0) = 6e5;
    RenderSettings st = small_settings(40, 24);
    st.camera.position = {{10000, -4000, 9000}};
    st.camera.look_at = {{10000, 10000, 2000}};
    const LayerResult start = render_layer(s, st, nullptr);
    s.vortex_table = std::make_shared<const Field2D>(std::move(table));
    EXPECT_TRUE(same_bytes(render_layer(s, st, nullptr).image, start.image)) << "time 0: no turn";
    s.time = 2 * std::numbers::pi / 0.01f;
    const LayerResult full = render_layer(s, st, nullptr);
    s.time = std::numbers::pi / 0.01f;
    const LayerResult half = render_layer(s, st, nullptr);
    double d_full = 0, d_half = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 40; ++x) {
            d_full = std::max(d_full, std::fabs(double(full.image.at(3, x, y)) - start.image.at(3, x, y)));
            d_half = std::max(d_half, std::fabs(double(half.image.at(3, x, y)) - start.image.at(3, x, y)));
        }
    EXPECT_LT(d_full, 0.02);
    EXPECT_GT(d_half, 0.2);
    const auto f = full.report.active_features();
    EXPECT_NE(std::find(f.begin(), f.end(), "vortex_rings"), f.end());
    // Half a turn: cloud where the west half has it (the noise turned), none over the
    // east half, which a turned map would have covered with the west's clouds.
    std::vector<Vec3d> west, east;
    for (int i = 0; i < 30; ++i)
        for (int k = 0; k < 10; ++k) {
            const double y = 1000 + 600.0 * i, h = 1700 + 200.0 * k;
            west.push_back({{3000, y, h}});
            east.push_back({{17000, y, h}});
        }
    const std::vector<double> dw = layer_density(s, west), de = layer_density(s, east);
    EXPECT_GT(*std::max_element(dw.begin(), dw.end()), 0.05);
    EXPECT_EQ(*std::max_element(de.begin(), de.end()), 0.0);
}

TEST(LayerVortex, TheTurnsCentreMovesWithTheMapsWindScroll) {
    // With wind the map scrolls by wind * time, and the storm's centre with it:
    // on the vertical through the scrolled centre the noise turns about itself (the
    // layer is the unturned one, exactly); through the table's own centre it does not.
    LayerScene s = scene_with(0.7);
    s.wind = {{4, 0}};
    s.time = 500; // 2 km downwind
    s.cloud_top_offset = 0;
    s.earth_radius = 1e12; // a flat shell: the points' altitude is their z
    const LayerScene plain = s;
    Field2D table({{1, 1}}, 5, Box2d{{{0, 0}}, {{20000, 20000}}}, {"inner", "outer", "speed", "skew", "overlap_end"});
    table.at(0, 0, 0) = 0;
    table.at(1, 0, 0) = 5e5;
    table.at(2, 0, 0) = 0.003f; // 1.5 rad at time 500
    table.at(4, 0, 0) = 6e5;
    s.vortex_table = std::make_shared<const Field2D>(std::move(table));
    std::vector<Vec3d> moved, fixed;
    for (int k = 0; k < 60; ++k) {
        moved.push_back({{12000, 10000, 1550.0 + 40 * k}});
        for (double dy : {-900.0, 900.0}) fixed.push_back({{10000, 10000 + dy, 1550.0 + 40 * k}});
    }
    const std::vector<double> m = layer_density(s, moved), m0 = layer_density(plain, moved);
    for (size_t i = 0; i < m.size(); ++i) EXPECT_EQ(m[i], m0[i]) << i;
    EXPECT_GT(*std::max_element(m.begin(), m.end()), 0.0);
    const std::vector<double> f = layer_density(s, fixed), f0 = layer_density(plain, fixed);
    double moved_most = 0;
    for (size_t i = 0; i < f.size(); ++i) moved_most = std::max(moved_most, std::fabs(f[i] - f0[i]));
    EXPECT_GT(moved_most, 0.05) << "off the scrolled centre the noise turns";
}

TEST(LayerAnvil, TheAnvilRisesAboveMaxHeightOnlyWhereTheBiasIsPositiveAndAtMostItsLift) {
    // Uniform cumulonimbus 1500..4000 m, no noise; an anvil map with bias 1
    // and lift L on the west half (x < 8 km), 0 on the east. Analytic
    // expectation: above 4000 m there is density only where the bilinear bias
    // is > 0, never at or above 4000 + lift(x) there, and the lower part of
    // the raised band (f = 0.75 of the raised column) is cloudy in the west.
    LayerScene s = scene_with(0.8, false, 1.0);
    s.wind = {{0, 0}};
    s.cloud_top_offset = 0;
    const double L = 1500;
    Field2D anvil({{20, 20}}, 2, s.ndf->bounds(), {"anvil_bias", "anvil_lift"});
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const bool west = x < 8;
            anvil.at(0, x, y) = west ? 1.0f : 0.0f;
            anvil.at(1, x, y) = west ? float(L) : 0.0f;
        }
    const LayerScene plain = s;
    s.anvil = std::make_shared<const Field2D>(anvil);
    EXPECT_NEAR(layer_shell(plain).top, 4000, 1e-9);
    EXPECT_NEAR(layer_shell(s).top, 4000 + L, 1e-9);
    std::vector<Vec3d> pts;
    for (int i = 0; i < 40; ++i)
        for (int k = 0; k < 40; ++k) pts.push_back({{250.0 + 500.0 * i, 10000.0, 4000.0 + 50.0 * k}});
    place_at_altitude(pts);
    const std::vector<double> d = layer_density(s, pts), d0 = layer_density(plain, pts);
    int west_cloudy = 0;
    for (size_t j = 0; j < pts.size(); ++j) {
        const double x = pts[j][0], h = 4000.0 + 50.0 * double(j % 40);
        EXPECT_EQ(d0[j], 0.0) << "no anvil: nothing at or above max_height";
        // Bias of the 20-texel map (1 km texels, centres at 500 + 1000 i), bilinear, clamped.
        const double u = std::clamp(x / 1000.0 - 0.5, 0.0, 19.0);
        const int i0 = int(u);
        const double t = u - i0;
        const double bias = (i0 < 8 ? 1.0 : 0.0) * (1 - t) + (std::min(i0 + 1, 19) < 8 ? 1.0 : 0.0) * t;
        if (bias <= 0) {
            EXPECT_EQ(d[j], 0.0) << "x " << x << " h " << h;
        }
        if (h >= 4000 + L * bias) {
            EXPECT_EQ(d[j], 0.0) << "x " << x << " h " << h;
        }
        if (x < 7000 && h > 4000 && h < 4000 + 0.7 * L && d[j] > 0) ++west_cloudy;
    }
    EXPECT_GT(west_cloudy, 100);
    // A map without the lift channel lifts nothing (the old maps' meaning).
    Field2D bias_only({{20, 20}}, 1, s.ndf->bounds(), {"anvil_bias"});
    for (float& v : bias_only.channel(0)) v = 1.0f;
    s.anvil = std::make_shared<const Field2D>(std::move(bias_only));
    for (double v : layer_density(s, pts)) EXPECT_EQ(v, 0.0);
}

TEST(LayerVortex, SkewTurnsTheRingPatternByItsAngleTimesTheHeightFraction) {
    // At time 0 one ring with skew k over the whole map: over a uniform map the
    // layer at altitude h equals the layer without rings with its noise turned by
    // k * phi about the ring centre, phi = (h - 1500) / (4000 - 1500). Checked at
    // points by rotating them by hand.
    LayerScene s = scene_with(0.0);
    Field2D set = *s.ndf;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) set.at(ndf::Coverage, x, y) = 0.7f; // the map is the same turned: the noise shows the turn
    s.ndf = std::make_shared<const Field2D>(std::move(set));
    s.wind = {{0, 0}};
    s.cloud_top_offset = 0;
    const LayerScene plain = s;
    const double k = 1.2;
    Field2D table({{1, 1}}, 5, Box2d{{{0, 0}}, {{20000, 20000}}}, {"inner", "outer", "speed", "skew", "overlap_end"});
    table.at(0, 0, 0) = 0;
    table.at(1, 0, 0) = 5e5;
    table.at(2, 0, 0) = 0.01f; // no effect at time 0
    table.at(3, 0, 0) = float(k);
    table.at(4, 0, 0) = 6e5;
    s.vortex_table = std::make_shared<const Field2D>(std::move(table));
    const Vec3d C{{10000, 10000, -kR}};
    auto on_sphere = [&](double x, double y, double h) {
        const Vec3d d{{x - C[0], y - C[1], -C[2]}};
        const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        return Vec3d{{C[0] + d[0] / n * (kR + h), C[1] + d[1] / n * (kR + h), C[2] + d[2] / n * (kR + h)}};
    };
    std::vector<Vec3d> pts, turned;
    for (int a = 0; a < 24; ++a)
        for (int r = 1; r <= 4; ++r)
            for (double h : {1700.0, 2500.0, 3300.0}) {
                const double ang = a * std::numbers::pi / 12, rad = 1500.0 * r;
                const Vec3d p = on_sphere(10000 + rad * std::cos(ang), 10000 + rad * std::sin(ang), h);
                pts.push_back(p);
                // Read where the pattern came from: turned by -k phi about the centre (x, y only).
                const double phi = (h - 1500) / 2500, c = std::cos(-k * phi), sn = std::sin(-k * phi);
                const double dx = p[0] - 10000, dy = p[1] - 10000;
                turned.push_back({{10000 + c * dx - sn * dy, 10000 + sn * dx + c * dy, p[2]}});
            }
    const std::vector<double> got = layer_density(s, pts), want = layer_density(plain, turned), unturned = layer_density(plain, pts);
    double diff = 0, moved = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        EXPECT_NEAR(got[i], want[i], 1e-6) << i;
        diff = std::max(diff, std::fabs(got[i] - want[i]));
        moved = std::max(moved, std::fabs(got[i] - unturned[i]));
    }
    EXPECT_GT(moved, 0.1) << "the skew must change the layer";
    // The picture shows it too, and reports the rings.
    RenderSettings st = small_settings(32, 18);
    st.camera.position = {{10000, -4000, 9000}};
    st.camera.look_at = {{10000, 10000, 2000}};
    const LayerResult r = render_layer(s, st, nullptr);
    EXPECT_TRUE(r.report.vortex);
    EXPECT_FALSE(same_bytes(r.image, render_layer(plain, st, nullptr).image));
}

TEST(LayerSky, HorizonStripWrapsAroundTheCameraFromTheHorizonUpAtItsTexelSize) {
    // Far Cry 6's cirrus horizon strip on a cylinder around the camera: x the azimuth
    // from +x toward +y, row 0 the horizon, rows up at the width's texel size
    // (tan(elevation) x W / 2 pi rows). A 64 x 8 strip, 1 only at azimuths 45-135
    // degrees (x 8..23) in rows 0-3: rows 0-3 reach tan(e) = 4 x 2 pi / 64, e = 21.4
    // degrees, the strip's top (row 8) 38.1 degrees.
    Field2D strip({{64, 8}}, 1, Box2d{{{0, 0}}, {{1, 1}}}, {"cirrus_horizon"});
    for (int y = 0; y < 4; ++y)
        for (int x = 8; x < 24; ++x) strip.at(0, x, y) = 1.0f;
    LayerScene clear = scene_with(0.0, false);
    clear.haze_distance = 0;
    LayerScene with = clear;
    SkyLayer l;
    l.mapping = SkyMapping::Cylinder;
    l.texture = std::make_shared<const Field2D>(std::move(strip));
    l.opacity = 0.8;
    with.sky_layers.push_back(l);
    // One pixel looking along (azimuth, elevation) from the ground.
    auto pixel = [&](const LayerScene& sc, double az_deg, double el_deg) {
        RenderSettings st = small_settings(1, 1);
        st.camera.fov_deg = 1;
        const double a = az_deg * std::numbers::pi / 180, e = el_deg * std::numbers::pi / 180;
        st.camera.position = {{10000, 10000, 2}};
        st.camera.look_at = {{10000 + 1000 * std::cos(e) * std::cos(a), 10000 + 1000 * std::cos(e) * std::sin(a), 2 + 1000 * std::sin(e)}};
        const LayerResult r = render_layer(sc, st, nullptr);
        return Vec3d{{r.image.at(0, 0, 0), r.image.at(1, 0, 0), r.image.at(2, 0, 0)}};
    };
    auto differs = [](const Vec3d& a, const Vec3d& b) { return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]); };
    // Toward +y (azimuth 90) low: the strip's cloud, whiter than the blue sky.
    const Vec3d lit = pixel(with, 90, 8), sky = pixel(clear, 90, 8);
    EXPECT_GT(differs(lit, sky), 0.05);
    EXPECT_GT(lit[0] - lit[2], sky[0] - sky[2]) << "cloud is less blue than the sky";
    // Elsewhere around, above row 4 and above the strip: the sky alone, exactly.
    for (const auto& [az, el] : std::vector<std::pair<double, double>>{{270, 8}, {0, 8}, {180, 8}, {90, 30}, {90, 45}}) {
        const Vec3d a = pixel(with, az, el), b = pixel(clear, az, el);
        EXPECT_EQ(a[0], b[0]) << az << ", " << el;
        EXPECT_EQ(a[1], b[1]) << az << ", " << el;
        EXPECT_EQ(a[2], b[2]) << az << ", " << el;
    }
    // Just inside and outside the cloud's rows at azimuth 90: row 4 is at 21.4 degrees.
    EXPECT_GT(differs(pixel(with, 90, 18), pixel(clear, 90, 18)), 0.05);
    EXPECT_LT(differs(pixel(with, 90, 24), pixel(clear, 90, 24)), 1e-6);
    // Below the horizon: nothing of it.
    const Vec3d g = pixel(with, 90, -5), g0 = pixel(clear, 90, -5);
    EXPECT_EQ(g[0], g0[0]);
}

TEST(LayerMap, AClearTexelsHeightsDrawNoSheetToItsCloudyNeighbour) {
    // West half 1500..4000 m at coverage 0.8, no noise; east half 9000..11000 m.
    // Clear (coverage 0) in the east, the east's heights mean nothing: between
    // the two texel centres there is cloud only under 4000 m, fading out with
    // the coverage. (Lerping the heights drew a sheet rising from 4 to 9 km
    // across the texel, a few metres thick where a ray crossed it: the
    // superstorm's veils that the march hit at random.) Cloudy in the east
    // too, the heights interpolate as before: the midpoint's column is
    // 5250..7500 m.
    for (const double east_coverage : {0.0, 0.8}) {
        LayerScene s = scene_with(0.8, false, 1.0);
        s.wind = {{0, 0}};
        s.cloud_top_offset = 0;
        Field2D set = *s.ndf;
        for (int y = 0; y < 16; ++y)
            for (int x = 8; x < 16; ++x) {
                set.at(ndf::Coverage, x, y) = float(east_coverage);
                set.at(ndf::MinHeight, x, y) = 9000.0f;
                set.at(ndf::MaxHeight, x, y) = 11000.0f;
            }
        s.ndf = std::make_shared<const Field2D>(std::move(set));
        // Texel centres 7 and 8 are at x = 9375 and 10625 m (1250 m texels).
        std::vector<Vec3d> pts;
        for (int i = 0; i <= 20; ++i)
            for (int k = 0; k < 200; ++k) pts.push_back({{9375.0 + 62.5 * i, 10000.0, 1500.0 + 50.0 * k}});
        place_at_altitude(pts);
        const std::vector<double> d = layer_density(s, pts);
        int low = 0, high = 0, mid_band = 0;
        for (size_t j = 0; j < pts.size(); ++j) {
            const int i = int(j / 200);
            const double h = 1500.0 + 50.0 * double(j % 200);
            ASSERT_TRUE(std::isfinite(d[j]));
            if (d[j] > 0) (h < 4000 ? low : high)++;
            if (i == 10 && h > 5400 && h < 7400 && d[j] > 0) ++mid_band;
        }
        if (east_coverage == 0) {
            EXPECT_EQ(high, 0) << "cloud above the cloudy texel's top between it and a clear texel";
            EXPECT_GT(low, 20 * 20) << "the west cloud fades out across the texel at its own heights";
            EXPECT_EQ(mid_band, 0);
        } else {
            EXPECT_GT(mid_band, 20) << "two cloudy texels: the heights interpolate";
        }
    }
}

// The sky occlusion's mean density (LayerModel::mean_density, a table over
// profile and coverage) against brute force: the cheap density averaged over
// the base noise's whole tile (a plane of points across its x and y, the
// wind's time rise stepping the plane through its z), at several heights and
// coverages. Without base noise it is the density itself.
TEST(LayerMeanDensity, IsTheCheapDensityAveragedOverTheNoise) {
    for (double coverage : {0.3, 0.6, 0.9}) {
        LayerScene s = scene_with(coverage);
        s.detail_noise = nullptr; // layer_density's full sample is then the cheap one
        s.curl = nullptr;
        s.wind = {{10, 0}}; // the noise rises 0.1 x 10 m per second of time
        for (double h : {1900.0, 2500.0, 3000.0}) {
            std::vector<Vec3d> plane;
            const int n = 48; // over one 6 km base tile: 125 m apart, the 32^3 noise's 188 m texels
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) plane.push_back({{7000 + (i + 0.5) * s.base_tile / n, 7000 + (j + 0.5) * s.base_tile / n, h}});
            place_at_altitude(plane);
            double brute = 0;
            const int slices = 64;
            for (int k = 0; k < slices; ++k) {
                s.time = (k + 0.5) * s.base_tile / slices; // a rise of base_tile / slices metres each
                for (double v : layer_density(s, plane)) brute += v;
            }
            brute /= double(plane.size()) * slices;
            const double mean = layer_mean_density(s, {plane[0]})[0];
            const double elsewhere = layer_mean_density(s, {plane[plane.size() / 2]})[0];
            std::printf("coverage %.1f altitude %.0f: mean %.4f, brute force %.4f\n", coverage, h, mean, brute);
            EXPECT_GT(brute, 0.0) << coverage << " " << h;
            EXPECT_NEAR(mean, brute, 0.05 * brute + 0.001) << "coverage " << coverage << ", altitude " << h;
            EXPECT_DOUBLE_EQ(mean, elsewhere) << "the mean is the map's, not the noise's: the same over a uniform map";
        }
    }
    // No base noise: the mean is the density.
    LayerScene plain = scene_with(0.6, false);
    std::vector<Vec3d> pts{{{9000, 9000, 2000}}, {{12000, 8000, 3000}}};
    place_at_altitude(pts);
    EXPECT_EQ(layer_mean_density(plain, pts), layer_density(plain, pts));
}
