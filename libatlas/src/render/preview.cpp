// One preview for any graph (atlas/render/preview.h): the 2.5D scene, the
// daylight looks and the point-light syntax shared by the CLI and the node.
#include "atlas/render/preview.h"

#include "atlas/core/error.h"
#include "atlas/ndf/cone_map.h"
#include "atlas/ndf/vertical_profile.h"

#include <algorithm>
#include <chrono>
#include <numbers>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace atlas::render {

bool is_ndf_set(const Field2D& f) {
    return f.find_channel("coverage") >= 0 && f.find_channel("min_height") >= 0 && f.find_channel("max_height") >= 0;
}

bool is_weather_map(const Field2D& f) { return f.find_channel("coverage") >= 0 && !is_ndf_set(f) && f.find_channel("cumulus") < 0; }

Field2DPtr weather_map_as_set(const Field2D& m) {
    std::vector<std::string> names{"coverage", "type", "precipitation", "min_height", "max_height"};
    Field2D f(m.resolution(), int(names.size()), m.bounds(), names);
    const int ct = m.find_channel("type"), cp = m.find_channel("precipitation"), cc = m.find_channel("coverage");
    if (cc < 0) throw Error("render (2.5D): a weather map needs a 'coverage' channel");
    for (int y = 0; y < m.height(); ++y)
        for (int x = 0; x < m.width(); ++x) {
            f.at(0, x, y) = m.at(cc, x, y);
            f.at(1, x, y) = ct >= 0 ? m.at(ct, x, y) : 0.5f;
            f.at(2, x, y) = cp >= 0 ? m.at(cp, x, y) : 0.0f;
            f.at(3, x, y) = 1500;
            f.at(4, x, y) = 4000;
        }
    return std::make_shared<const Field2D>(std::move(f));
}

SkyLayer sky_layer_from(Field2DPtr tex, int channel, double altitude, double tile, double opacity) {
    if (!tex || channel < 0 || channel >= tex->channels()) throw Error("render (2.5D): sky layer texture missing or channel out of range");
    SkyLayer l;
    l.texture = tex;
    l.channel = channel;
    l.altitude = altitude;
    l.tile = tile;
    l.opacity = opacity;
    auto ch = tex->channel(channel);
    double sum = 0, sq = 0;
    for (float v : ch) sum += v, sq += double(v) * v;
    const double n = double(ch.size()), mean = sum / n, sd = std::sqrt(std::max(0.0, sq / n - mean * mean));
    l.value_min = mean;
    l.value_max = mean + 2 * std::max(sd, 1e-6);
    l.wind = {{3, 1}};
    return l;
}

LayerScene layer_preview_scene(const LayerPreviewInputs& in) {
    LayerScene layer;
    if (in.ndf) layer.ndf = is_ndf_set(*in.ndf) ? in.ndf : weather_map_as_set(*in.ndf);
    else {
        // Only 2D layers: an empty cloud layer under them.
        Field2D empty({{2, 2}}, 3, Box2d{{{0, 0}}, {{40000, 40000}}}, {"coverage", "min_height", "max_height"});
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) empty.at(1, x, y) = 1500, empty.at(2, x, y) = 4000;
        layer.ndf = std::make_shared<const Field2D>(std::move(empty));
    }
    layer.profile_lut = in.profile_lut ? in.profile_lut
                                       : std::make_shared<const Field2D>(ndf::build_profile_lut(ndf::VerticalProfile{}, 97, 128, nullptr));
    layer.base_noise = in.base_noise;
    layer.detail_noise = in.detail_noise;
    layer.curl = in.curl;
    layer.envelope.cone_map = in.cone_map;
    layer.envelope.distance_map = in.distance_map;
    layer.anvil = in.anvil;
    layer.vortex_table = in.vortex_table;
    auto tile_of = [](const Field2D& f) {
        const double sx = f.bounds().max[0] - f.bounds().min[0];
        return sx > 100 ? sx : 20000.0; // unit-box textures: 20 km per tile
    };
    if (in.cirrus) {
        const int c = in.cirrus->find_channel("cirrus");
        layer.sky_layers.push_back(sky_layer_from(in.cirrus, c >= 0 ? c : 0, 8000, tile_of(*in.cirrus), 0.8));
    }
    if (in.sky_texture) layer.sky_layers.push_back(sky_layer_from(in.sky_texture, 0, 6000, tile_of(*in.sky_texture), 0.9));
    if (in.horizon_strip) {
        // Its values are coverage already (0 to 1, fading to 0 at the top): no window.
        SkyLayer l;
        l.mapping = SkyMapping::Cylinder;
        l.texture = in.horizon_strip;
        l.opacity = 0.8;
        layer.sky_layers.push_back(l);
    }
    // A storm is one feature: no copies of it beyond the map. Weather maps tile.
    // Every NDF set carries a storm channel (all zero in a weather map, so
    // its presence says nothing); a storm's graph also gives an anvil map or
    // vortex rings, which stay at frames where its storm has not formed yet
    // (a lifecycle's first and last): the edge holds through a sequence.
    bool storm = in.anvil != nullptr || in.vortex_table != nullptr;
    if (const int cs = layer.ndf->find_channel("superstorm_coverage"); cs >= 0 && !storm) {
        const auto ch = layer.ndf->channel(cs);
        storm = std::any_of(ch.begin(), ch.end(), [](float v) { return v > 0; });
    }
    layer.edge = storm ? MapEdge::Empty : MapEdge::Wrap;
    validate_layer_scene(layer);
    return layer;
}

Field2DPtr cloud_top_cone_map(const Field2D& set) {
    const int cc = set.find_channel("coverage"), cm = set.find_channel("max_height");
    if (cc < 0 || cm < 0) throw Error("render (2.5D): the cone map needs an NDF set with coverage and max_height");
    const int w = set.width(), h = set.height();
    const int k = std::max(1, (std::max(w, h) + 127) / 128);
    const int pw = (w + k - 1) / k, ph = (h + k - 1) / k;
    Field2D pooled({{pw, ph}}, 1, set.bounds(), {"top"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (set.at(cc, x, y) > 0) pooled.at(0, x / k, y / k) = std::max(pooled.at(0, x / k, y / k), set.at(cm, x, y));
    Field2D tops({{pw, ph}}, 1, set.bounds(), {"top"});
    for (int y = 0; y < ph; ++y)
        for (int x = 0; x < pw; ++x) {
            float top = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) top = std::max(top, pooled.at(0, std::clamp(x + dx, 0, pw - 1), std::clamp(y + dy, 0, ph - 1)));
            tops.at(0, x, y) = top;
        }
    ndf::ConeMapOptions o;
    o.robust = true;
    o.texel_size = std::min((set.bounds().max[0] - set.bounds().min[0]) / pw, (set.bounds().max[1] - set.bounds().min[1]) / ph);
    return std::make_shared<const Field2D>(ndf::cone_map(tops, 0, o, nullptr));
}

namespace {
void daylight(RenderSettings& s) {
    s.sky_colour = {{0.07f, 0.17f, 0.50f}};
    s.sky_horizon = Vec3f{{0.45f, 0.55f, 0.70f}};
    s.sun_direction = sun_direction(kPreviewSunAzimuthDeg, kPreviewSunElevationDeg);
    s.sun_colour = {{2.6f, 2.45f, 2.25f}};
}
} // namespace

RenderSettings layer_preview_settings(const LayerScene& scene, int width, int height, LayerView view, double azimuth_deg, double elevation_deg) {
    RenderSettings s = preview_settings(Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, width, height);
    s.camera = layer_camera(scene, view, double(width) / height, azimuth_deg, elevation_deg);
    daylight(s);
    s.multiple_scattering = 0.8;
    return s;
}

void apply_voxel_daylight(RenderSettings& s) {
    daylight(s);
    s.multiple_scattering = 0.3;
    s.ambient_strength = 0.7;
}

std::vector<PointLight> parse_point_lights(const std::string& text) {
    std::vector<PointLight> lights;
    std::stringstream all(text);
    for (std::string item; std::getline(all, item, ';');) {
        std::string spaced = item;
        std::replace(spaced.begin(), spaced.end(), ',', ' ');
        std::stringstream one(spaced);
        std::vector<double> v;
        bool ok = true;
        for (std::string t; one >> t;) {
            char* end = nullptr;
            v.push_back(std::strtod(t.c_str(), &end));
            ok = ok && end != t.c_str() && *end == '\0' && std::isfinite(v.back());
        }
        // Two commas in a row leave an empty number: not a light.
        ok = ok && item.find(",,") == std::string::npos;
        if (v.empty() && ok) continue;
        if (!ok || (v.size() != 7 && v.size() != 8))
            throw Error("lights: expected 'X,Y,Z,R,G,B,INTENSITY[,RADIUS]' (7 or 8 finite numbers, commas or spaces) per light, lights separated by ';', got '" +
                        item + "'");
        PointLight l;
        l.position = {{v[0], v[1], v[2]}};
        l.colour = {{float(v[3]), float(v[4]), float(v[5])}};
        l.intensity = v[6];
        l.radius = v.size() == 8 ? v[7] : 0.0;
        lights.push_back(l);
    }
    return lights;
}


namespace {

// The clouds' occupied box and, when asked, the centre of the voxel column
// (x, y) holding the most cloud (profile > 0) at the height of its middle,
// the first such column in index order on ties. One pass over the grid serves
// both where the profile decides the box (its grid is the SDF's).
struct CloudExtent {
    Box3d bounds;
    Vec3d heaviest{{0, 0, 0}};
};

Vec3d heaviest_of(const Field3D& f, const std::vector<int>& count) {
    const size_t best = size_t(std::max_element(count.begin(), count.end()) - count.begin());
    return f.voxel_center(int(best % size_t(f.nx())), int(best / size_t(f.nx())), f.nz() / 2);
}

CloudExtent scan_clouds(const CloudScene& scene, bool want_column) {
    // Where the profile is positive (an NVDF's profile is positive exactly
    // inside its SDF; a density grid's SDF is a conservative bound several
    // voxels wider, which made its clouds look small in the frame).
    const Field3D& sdf = *scene.sdf;
    const bool profile = scene.modeling && (scene.modeling->resolution() == sdf.resolution() || scene.sdf_block > 1) &&
                         scene.modeling->channels() > 0;
    const Field3D& f = profile ? *scene.modeling : sdf;
    const int c = profile ? std::max(0, f.find_channel("dimensional_profile")) : std::max(0, sdf.find_channel("sdf")); // as the sampler picks them
    auto inside = [&](int x, int y, int z) { return profile ? f.at(c, x, y, z) > 0 : f.at(c, x, y, z) < 0; };
    std::vector<int> count(want_column && profile ? size_t(f.nx()) * f.ny() : 0, 0);
    Vec3i lo{{f.nx(), f.ny(), f.nz()}}, hi{{-1, -1, -1}};
    for (int z = 0; z < f.nz(); ++z)
        for (int y = 0; y < f.ny(); ++y)
            for (int x = 0; x < f.nx(); ++x)
                if (inside(x, y, z)) {
                    lo = {{std::min(lo[0], x), std::min(lo[1], y), std::min(lo[2], z)}};
                    hi = {{std::max(hi[0], x), std::max(hi[1], y), std::max(hi[2], z)}};
                    if (!count.empty()) ++count[size_t(y) * f.nx() + x];
                }
    CloudExtent e;
    const Box3d b = f.bounds();
    if (hi[0] < 0) {
        e.bounds = b;
    } else {
        const Vec3d v = f.voxel_size();
        for (int a = 0; a < 3; ++a) {
            e.bounds.min[a] = b.min[a] + lo[a] * v[a];
            e.bounds.max[a] = b.min[a] + (hi[a] + 1) * v[a];
        }
    }
    if (want_column && profile) {
        e.heaviest = heaviest_of(f, count);
    } else if (want_column) {
        // The modeling grid differs from the SDF's: count its own profile.
        const Field3D& m = *scene.modeling;
        const int cp = std::max(0, m.find_channel("dimensional_profile"));
        std::vector<int> mc(size_t(m.nx()) * m.ny(), 0);
        for (int z = 0; z < m.nz(); ++z)
            for (int y = 0; y < m.ny(); ++y)
                for (int x = 0; x < m.nx(); ++x)
                    if (m.at(cp, x, y, z) > 0) ++mc[size_t(y) * m.nx() + x];
        e.heaviest = heaviest_of(m, mc);
    }
    return e;
}

} // namespace

Box3d cloud_bounds(const CloudScene& scene) { return scan_clouds(scene, false).bounds; }

namespace {

// The voxel view presets (ground, aerial, orbit) over the clouds' box.
Camera voxel_camera(const CloudScene& scene, PreviewView view, double aspect, double azimuth, double elevation) {
    const bool ground_view = view == PreviewView::Ground || view == PreviewView::Auto;
    const CloudExtent clouds = scan_clouds(scene, ground_view);
    const Box3d& b = clouds.bounds;
    if (ground_view) {
        // From the ground south of the clouds, 2 m up (or under the lowest base
        // when the clouds float high), pitched up at the bases and the lit
        // flanks: how cumulus is seen and photographed. A cloud (not a field):
        // far enough back that it fills about half the frame height (issue 41:
        // a third to two thirds; at 0.1 of its depth it overflowed the frame).
        Camera c;
        c.fov_deg = 60;
        const Vec3d size = b.max - b.min;
        const double ground = scene.modeling->bounds().min[2];
        const double cz = std::max(ground + 2.0, b.min[2] - 0.25 * size[2]);
        const Vec3d& heavy = clouds.heaviest; // the biggest cloud: the column holding the most cloud
        if (std::max(size[0], size[1]) > 4 * size[2]) {
            // A field of clouds (far wider than tall): stand at its south edge
            // and look up across it toward its biggest cloud, the sky
            // photographed from under it (the field fills a third or more).
            c.position = {{heavy[0], b.min[1] - 0.1 * size[1], cz}};
            c.look_at = {{heavy[0], 0.5 * (b.min[1] + b.max[1]), b.max[2] + 0.25 * size[2]}};
            return c;
        }
        const double half = 0.5 * c.fov_deg * std::numbers::pi / 180;
        const double target = half; // the clouds' angular height: half the field of view
        auto extent = [&](double d) { return std::atan2(b.max[2] - cz, d) - std::atan2(b.min[2] - cz, d); };
        // With the camera under the bases the extent first grows with the distance (straight
        // below, the cloud is a sliver overhead), peaks at sqrt(above top x above base), then
        // falls: search the falling side only (searching from 0 stood the camera under the
        // cloud of a field whose bases float high).
        const double peak = b.min[2] > cz ? std::sqrt((b.max[2] - cz) * (b.min[2] - cz)) : 0.0;
        double lo = std::max(1e-3, peak), hi = std::max(1e7, 2 * lo); // extent falls as the distance grows from lo
        for (int i = 0; i < 100; ++i) {
            const double mid = std::sqrt(lo * hi);
            (extent(mid) > target ? lo : hi) = mid;
        }
        (void)aspect; // a field wider than the frame runs past its sides, as a photographed sky does
        const double d = hi;
        const double pitch = 0.5 * (std::atan2(b.max[2] - cz, d) + std::atan2(b.min[2] - cz, d));
        // Facing the biggest cloud from the south, at that distance from it;
        // nearer clouds stand in front of it. The box's centre line missed
        // sparse scenes (two towers and a puff 4 km apart).
        c.position = {{heavy[0], heavy[1] - d, cz}};
        c.look_at = {{heavy[0], heavy[1], cz + d * std::tan(pitch)}};
        return c;
    }
    if (view == PreviewView::Aerial) return framing_camera(b, aspect, 30, 55);
    return framing_camera(b, aspect, azimuth, elevation);
}

// A plain density grid's units: cloud water (kg/kg) becomes density for the
// preview's extinction; a picture that would be nearly empty says why.
void density_grid_units(CloudScene& scene, const PreviewOptions& o, std::vector<std::string>& notes) {
    const double dmax = *scene.density_grid_max;
    const bool kgkg = o.density_units == DensityUnits::KgPerKg || (o.density_units == DensityUnits::Auto && dmax > 0 && dmax < 0.02);
    double densest = dmax;
    if (kgkg && dmax > 0 && o.extinction > 0) {
        // Liquid water content = mixing ratio x air density (1 kg/m3 declared); extinction
        // 3 LWC / (2 rho_water r_eff) = 150 LWC per metre for 10 um droplets.
        const double k = 150.0 / o.extinction;
        // density_grid_scene renders (profile x S)^0.6: scaling S by k^(1/0.6) scales the density by k.
        scene.uniform_density_scale = static_cast<float>(double(*scene.uniform_density_scale) * std::pow(k, 1.0 / 0.6));
        densest = dmax * k;
        char buf[256];
        std::snprintf(buf, sizeof buf, "density units: kg/kg cloud water (densest voxel %.3g%s): extinction 150 x mixing ratio per metre (%s)", dmax,
                      o.density_units == DensityUnits::Auto ? ", under 0.02" : "",
                      o.density_units == DensityUnits::Auto ? "--density-units density reads the values as density" : "--density-units kg/kg");
        notes.push_back(buf);
        // Optical depth per voxel past ~5: the artistic multiple-scattering terms
        // draw such cores as dark blotches, the physical model does not.
        const Vec3d v = scene.modeling->voxel_size();
        if (densest * o.extinction * std::min({v[0], v[1], v[2]}) > 5 && o.artistic)
            notes.push_back("density: the densest voxels are optically very thick (over 5 per voxel): --artistic off draws them best");
    }
    // The largest optical depth straight through the grid along an axis: the
    // densities density_grid_scene renders, (profile x S)^0.6, summed per line.
    const Field3D& m = *scene.modeling;
    const int cp = std::max(0, m.find_channel("dimensional_profile"));
    const double S = *scene.uniform_density_scale;
    const Vec3i r = m.resolution();
    const Vec3d h = m.voxel_size();
    const size_t nx = static_cast<size_t>(r[0]), ny = static_cast<size_t>(r[1]), nz = static_cast<size_t>(r[2]);
    std::vector<double> sx(ny * nz, 0.0), sy(nx * nz, 0.0), sz(nx * ny, 0.0);
    for (int z = 0; z < r[2]; ++z)
        for (int y = 0; y < r[1]; ++y)
            for (int x = 0; x < r[0]; ++x) {
                const double p = m.at(cp, x, y, z);
                if (!(p > 0)) continue;
                const double d = std::pow(p * S, 0.6);
                sx[size_t(z) * r[1] + y] += d * h[0];
                sy[size_t(z) * r[0] + x] += d * h[1];
                sz[size_t(y) * r[0] + x] += d * h[2];
            }
    double line = 0;
    for (const auto* v : {&sx, &sy, &sz})
        for (double t : *v) line = std::max(line, t);
    const double tau = o.extinction * line;
    if (tau < 0.1) {
        char buf[320];
        std::snprintf(buf, sizeof buf,
                      "density: the picture will be nearly empty: the densest line through the grid has an optical depth of %.3g at --extinction %g "
                      "(densest voxel %.3g); raise --extinction or set --density-units",
                      tau, o.extinction, densest);
        notes.push_back(buf);
    }
}

// Lightning over the layer: flashes placed by the set's storm (or rain, or coverage) channel,
// 20-60 % up the columns that can flash (in-cloud flashes).
Field3DPtr layer_lightning_probability(const Field2D& set) {
    int ch = -1;
    for (const char* name : {"superstorm_coverage", "precipitation", "coverage"}) {
        const int c = set.find_channel(name);
        if (c < 0) continue;
        auto d = set.channel(c);
        if (std::any_of(d.begin(), d.end(), [](float x) { return x > 0; })) {
            ch = c;
            break;
        }
    }
    if (ch < 0) throw Error("lightning: the NDF set has no storm, rain or coverage to place flashes in");
    const int cmn = set.find_channel("min_height"), cmx = set.find_channel("max_height");
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int y = 0; y < set.height(); ++y)
        for (int x = 0; x < set.width(); ++x)
            if (set.at(ch, x, y) > 0) lo = std::min(lo, double(set.at(cmn, x, y))), hi = std::max(hi, double(set.at(cmx, x, y)));
    const double z0 = lo + 0.2 * (hi - lo), z1 = lo + 0.6 * (hi - lo) + 1e-3;
    // Only columns whose cloud reaches down through the flash band: an anvil
    // sheet spread at 8.5-11 km drew flashes into the clear air under it
    // (unless no column does: then every column with a storm, as before).
    Field3DPtr all = layer_flash_probability(set, ch, z0, z1);
    auto spanning = std::make_shared<Field3D>(*all); // one channel, texel (x, y) at set.index(x, y)
    bool any = false;
    for (int y = 0; y < set.height(); ++y)
        for (int x = 0; x < set.width(); ++x) {
            float& v = spanning->channel(0)[set.index(x, y)];
            if (set.at(cmn, x, y) > z0 || set.at(cmx, x, y) < z1) v = 0;
            any = any || v > 0;
        }
    return any ? Field3DPtr(spanning) : all;
}

} // namespace

PreviewJob prepare_preview(std::optional<CloudScene> voxel, std::optional<LayerScene> layer, const PreviewOptions& o, PreviewLook look,
                           Field3DPtr flash_probability, int threads) {
    check_preview_options(o);
    if (!voxel && !layer) throw Error("preview: nothing to draw (no voxel scene and no 2.5D layer)");
    PreviewJob job;
    if (voxel) {
        voxel->noise_tile = o.noise_tile;
        validate_scene(*voxel);
        if (voxel->density_grid_max) density_grid_units(*voxel, o, job.notes);
    }
    if (layer) {
        layer->time = o.time;
        layer->earth_radius = o.earth_radius;
        layer->wind = o.wind;
        if (o.edge) layer->edge = *o.edge; // else layer_preview_scene's choice: Empty for a storm, else Wrap
        validate_layer_scene(*layer);
    }
    const int w = o.size[0], h = o.size[1];
    const Box3d bounds = voxel ? voxel->modeling->bounds() : Box3d{{{0, 0, 0}}, {{1, 1, 1}}};
    RenderSettings s = preview_settings(bounds, w, h);
    const double aspect = double(w) / h;
    if (layer) {
        const LayerView kind = o.view == PreviewView::Aerial   ? LayerView::Aerial
                               : o.view == PreviewView::Orbit  ? LayerView::Orbit
                               : o.view == PreviewView::Ground ? LayerView::Ground
                               : look == PreviewLook::Graph    ? LayerView::Ground
                                                               : LayerView::Orbit;
        // The 2.5D daylight look and camera preset.
        s = layer_preview_settings(*layer, w, h, kind, o.azimuth, o.elevation);
    } else if (o.view != PreviewView::Auto || look == PreviewLook::Graph) {
        s.camera = voxel_camera(*voxel, o.view, aspect, o.azimuth, o.elevation);
    } else {
        // The clouds, not the volume: a cloud in a 4-8 km box was a speck.
        s.camera = framing_camera(cloud_bounds(*voxel), aspect, o.azimuth, o.elevation);
    }
    s.threads = threads;
    // A graph's voxel clouds get the 2.5D mode's daylight.
    if (voxel && !layer && look == PreviewLook::Graph) apply_voxel_daylight(s);
    if (o.manual_camera) {
        s.camera.position = o.position;
        s.camera.look_at = o.look_at;
    }
    if (layer) {
        // Envelope skipping pays off looking down on the layer (a ground view
        // starts under the clouds, where the cone map over the tops cannot
        // help): auto = on when the camera is above the lowest cloud base.
        PreviewEnvelope env = o.envelope;
        if (env == PreviewEnvelope::Auto) {
            const int cmin = layer->ndf->find_channel("min_height");
            float lowest = std::numeric_limits<float>::infinity();
            for (float v : layer->ndf->channel(cmin)) lowest = std::min(lowest, v);
            env = s.camera.position[2] > lowest ? PreviewEnvelope::On : PreviewEnvelope::Off;
        }
        if (env == PreviewEnvelope::Off) layer->envelope = {};
        if (env == PreviewEnvelope::On && !layer->envelope.cone_map && layer->ndf->width() > 2) {
            const auto t = std::chrono::steady_clock::now();
            layer->envelope.cone_map = cloud_top_cone_map(*layer->ndf);
            char buf[128];
            std::snprintf(buf, sizeof buf, "envelope: cone map over the cloud tops (%dx%d) in %.2f s", layer->ndf->width(), layer->ndf->height(),
                          seconds_since(t));
            job.notes.push_back(buf);
        }
    }
    if (o.fov > 0) s.camera.fov_deg = o.fov;
    s.sun_direction = sun_direction(o.sun_azimuth, o.sun_elevation);
    if (o.sun_colour) s.sun_colour = *o.sun_colour;
    s.quality = o.quality;
    s.skip_empty_space = o.sdf_skipping;
    s.use_light_grid = o.light_lookup_grid;
    s.extinction = o.extinction;
    s.sky_occlusion = o.sky_occlusion;
    s.mode = o.mode;
    if (o.sky_colour) s.sky_colour = *o.sky_colour;
    if (o.sky_horizon) s.sky_horizon = *o.sky_horizon;
    s.lights.insert(s.lights.end(), o.lights.begin(), o.lights.end());
    if (!o.artistic) {
        s.artistic = false;
        s.ms_octaves = kPhysicalMsOctaves;
        s.ms_diffusion = true; // docs/render.md, "Multiple scattering by diffusion"
        s.multiple_scattering = 1;
        s.ambient_strength = 1;
        // One Henyey-Greenstein lobe with the dual lobe's mean cosine
        // (0.33 for the defaults): what a path tracer's volume offers
        // (Cycles 3.4 does not weight two scatter closures by their
        // densities), and what multiple scattering depends on.
        s.hg_forward = s.hg_forward_weight * s.hg_forward + (1 - s.hg_forward_weight) * s.hg_back;
        s.hg_forward_weight = 1;
    }
    if (!o.ms_octaves.empty()) {
        const std::vector<double>& v = o.ms_octaves;
        s.ms_octaves = static_cast<int>(v[0]);
        if (v.size() >= 4) s.ms_energy = v[1], s.ms_extinction = v[2], s.ms_anisotropy = v[3];
        if (v.size() == 5) s.ms_scatter_power = v[4];
    }
    if (o.ms_diffusion) s.ms_diffusion = *o.ms_diffusion;
    // Beside the diffusion term the octaves only have to carry the optically
    // thin parts (shade() takes the larger of the two): their own calibration
    // (b = 0.5, docs/render.md "Calibration against Cycles") reaches deep
    // into shadowed flanks the diffusion lights already, so there they fade
    // faster unless --ms-octaves names b (every Cycles scene improved:
    // superstorm 11.7 -> 11.4%, voxel quickstart 8.9 -> 6.7%).
    if (!s.artistic && s.ms_diffusion && o.ms_octaves.size() < 4) s.ms_extinction = kPhysicalMsExtinctionWithDiffusion;
    if (o.ms_diffusion_sweeps) s.ms_diffusion_sweeps = *o.ms_diffusion_sweeps;
    s.light_grid = o.light_grid;
    if (o.lightning && !flash_probability) {
        if (!layer) throw Error("lightning places flashes over a 2.5D layer; this preview has no NDF set");
        flash_probability = layer_lightning_probability(*layer->ndf);
    }
    if (flash_probability) {
        LightField f;
        f.probability = flash_probability;
        f.colour = o.flash_colour;
        f.intensity = o.flash_intensity;
        f.radius = o.flash_radius;
        f.seed = uint32_t(o.flash_seed);
        f.flash = int32_t(o.flash_index);
        f.count = int(o.flash_count);
        s.light_fields.push_back(f);
    }
    job.voxel = std::move(voxel);
    job.layer = std::move(layer);
    job.settings = std::move(s);
    job.exposure = o.exposure;
    job.pixel_size = o.pixel_size;
    return job;
}

namespace {
// `small` scaled up bilinearly to w x h (pixel centres mapped onto pixel centres,
// clamped at the edges): the picture of a preview marched at pixel_size > 1.
Field2D scale_up(const Field2D& small, int w, int h) {
    Field2D out({{w, h}}, small.channels(), small.bounds(), small.channel_names());
    const int sw = small.width(), sh = small.height();
    for (int y = 0; y < h; ++y) {
        const double fy = std::clamp((y + 0.5) * sh / h - 0.5, 0.0, double(sh - 1));
        const int y0 = std::min(int(fy), sh - 1), y1 = std::min(y0 + 1, sh - 1);
        const float ty = float(fy - y0);
        for (int x = 0; x < w; ++x) {
            const double fx = std::clamp((x + 0.5) * sw / w - 0.5, 0.0, double(sw - 1));
            const int x0 = std::min(int(fx), sw - 1), x1 = std::min(x0 + 1, sw - 1);
            const float tx = float(fx - x0);
            for (int c = 0; c < small.channels(); ++c) {
                const float a = small.at(c, x0, y0) + (small.at(c, x1, y0) - small.at(c, x0, y0)) * tx;
                const float b = small.at(c, x0, y1) + (small.at(c, x1, y1) - small.at(c, x0, y1)) * tx;
                out.at(c, x, y) = a + (b - a) * ty;
            }
        }
    }
    return out;
}
} // namespace

PreviewFrame render_preview(const PreviewJob& job, const ProgressSink* progress) {
    if (!job.voxel && !job.layer) throw Error("preview: nothing to draw (no voxel scene and no 2.5D layer)");
    if (job.pixel_size < 1 || job.pixel_size > 8) throw Error("preview: pixel_size must be 1..8, got " + std::to_string(job.pixel_size));
    // One ray per pixel_size x pixel_size block: the same camera (its vertical field of
    // view) over a smaller picture of about the same aspect.
    RenderSettings settings = job.settings;
    if (job.pixel_size > 1) {
        settings.width = std::max(1, (settings.width + job.pixel_size - 1) / job.pixel_size);
        settings.height = std::max(1, (settings.height + job.pixel_size - 1) / job.pixel_size);
    }
    std::optional<Field2D> image;
    std::optional<LayerReport> layer_report;
    std::optional<RenderReport> voxel_report;
    if (job.layer) {
        LayerResult r = render_layer(*job.layer, settings, progress);
        layer_report = r.report;
        image = std::move(r.image);
    }
    if (job.voxel) {
        RenderResult r = render_clouds(*job.voxel, settings, progress);
        voxel_report = r.report;
        image = image ? composite_over(r.image, *image, settings) : std::move(r.image);
    }
    if (job.pixel_size > 1) image = scale_up(*image, job.settings.width, job.settings.height);
    return PreviewFrame{std::move(*image), std::move(layer_report), std::move(voxel_report)};
}

} // namespace atlas::render
