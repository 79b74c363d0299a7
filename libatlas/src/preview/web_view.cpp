// `atlas view`: a graph's 2.5D cloudscape for @takram/three-clouds (web_view.h).
#include "atlas/preview/web_view.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/io/image.h"
#include "atlas/ndf/three_clouds.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

namespace atlas::preview {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// WGS84 equatorial radius: the scene sits at latitude 0, longitude 0.
constexpr double kEquatorRadius = 6378137.0;
constexpr int kShapeSize = 128, kDetailSize = 32; // three-clouds' CLOUD_SHAPE(_DETAIL)_TEXTURE_SIZE
// The built page (plugins/web/dist), copied into every folder.
constexpr std::array<const char*, 3> kBundleFiles{"index.html", "atlas_view.js", "atmosphere.js"};

// The first page file `dir` lacks, or null when it holds them all.
const char* missing_bundle_file(const fs::path& dir) {
    for (const char* f : kBundleFiles)
        if (!fs::is_regular_file(dir / f)) return f;
    return nullptr;
}

std::string base64(const std::string& bytes) {
    static constexpr char k[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const uint32_t b0 = uint8_t(bytes[i]), b1 = i + 1 < bytes.size() ? uint8_t(bytes[i + 1]) : 0u,
                       b2 = i + 2 < bytes.size() ? uint8_t(bytes[i + 2]) : 0u;
        const uint32_t v = (b0 << 16) | (b1 << 8) | b2;
        out += k[(v >> 18) & 63];
        out += k[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? k[v & 63] : '=';
    }
    return out;
}

// A one-channel volume as bytes in three-clouds' order (web_view.h): byte
// i + n (j + n k) holds Atlas's voxel (x = j, y = k, z = i).
std::string volume_bytes(const Field3D& v, int n, const char* what) {
    const Vec3i r = v.resolution();
    if (r[0] != n || r[1] != n || r[2] != n)
        throw Error(std::string("atlas view: three-clouds reads a ") + std::to_string(n) + "^3 " + what + " volume; the preview's is " +
                    std::to_string(r[0]) + "x" + std::to_string(r[1]) + "x" + std::to_string(r[2]));
    std::string out(size_t(n) * size_t(n) * size_t(n), '\0');
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                out[size_t(i) + size_t(n) * (size_t(j) + size_t(n) * size_t(k))] =
                    char(uint8_t(std::lround(std::clamp(double(v.at(0, j, k, i)), 0.0, 1.0) * 255.0)));
    return out;
}

double frac(double v) { return v - std::floor(v); }

json vec(std::initializer_list<double> v) { return json(std::vector<double>(v)); }

} // namespace

WebViewResult write_web_view(const GraphPreview& preview, const render::PreviewOptions& options, const fs::path& out_dir,
                             const WebViewOptions& how) {
    if (!preview.job.layer || !preview.job.layer->ndf)
        throw Error("atlas view: the graph writes no NDF set or weather map; three-clouds draws 2.5D cloud layers only "
                    "(voxel clouds: atlas preview)");
    if (const char* f = missing_bundle_file(how.bundle_dir))
        throw Error("atlas view: the page bundle " + (how.bundle_dir / f).string() + " is missing; build it with scripts/web.sh");
    const render::LayerScene& L = *preview.job.layer;
    if (!L.base_noise || !L.detail_noise || !L.curl) throw Error("atlas view: the preview has no base, detail or curl noise to export");

    const ndf::ThreeCloudsWeather w = ndf::three_clouds_weather(*L.ndf, *L.profile_lut, nullptr);
    const Box2d& b = L.ndf->bounds();
    const double size_x = b.max[0] - b.min[0], size_y = b.max[1] - b.min[1];
    const double cx = 0.5 * (b.min[0] + b.max[0]), cy = 0.5 * (b.min[1] + b.max[1]);
    // three-clouds' cube-sphere UV at the scene's place: u = 1/2 + east / (sqrt 2 |p|).
    const double radius = kEquatorRadius + 0.5 * (w.min_height + w.max_height);
    const double rep_x = std::numbers::sqrt2 * radius / size_x, rep_y = std::numbers::sqrt2 * radius / size_y;

    WebViewResult result;
    json layers = json::array();
    for (const ndf::ThreeCloudsLayer& l : w.layers) {
        json j = {{"channel", std::string(1, l.channel)},
                  {"altitude", l.altitude},
                  {"height", l.used ? l.height : 0.0},
                  // three-clouds saturates density * densityScale: its
                  // extinction per metre is Atlas's at density 1.
                  {"densityScale", options.extinction * L.density_scale},
                  {"shapeAmount", 1},
                  {"shapeDetailAmount", 1},
                  {"weatherExponent", 1},
                  {"shapeAlteringBias", l.shape_altering_bias},
                  // With coverage 1/2 and filter width 1/2, three-clouds'
                  // weather density at mid-layer is the channel's value.
                  {"coverageFilterWidth", 0.5},
                  {"densityProfile", {{"expTerm", 0}, {"exponent", 0}, {"linearTerm", 0}, {"constantTerm", 1}}},
                  {"shadow", l.used}};
        layers.push_back(j);
        if (l.used)
            result.log.push_back(std::string("layer ") + l.channel + " " + l.name + ": " + std::to_string(int(std::lround(l.altitude))) +
                                 " to " + std::to_string(int(std::lround(l.altitude + l.height))) + " m");
    }
    if (w.envelope_spread > 1)
        result.log.push_back("the set's envelope varies by up to " + std::to_string(int(std::lround(w.envelope_spread))) +
                             " m; three-clouds layers have one altitude (the coverage-weighted mean is used)");
    const double off_x = frac((cx - b.min[0]) / size_x - 0.5 * rep_x), off_y = frac((cy - b.min[1]) / size_y - 0.5 * rep_y);
    // three-clouds moves its shape down the surface normal by 2e4 m per unit of
    // weather offset (clouds "evolve" as the weather scrolls): put it back, so the
    // shape is sampled where Atlas samples its base noise.
    const double evolution = 2e4 * std::hypot(off_x, off_y);
    const double shape_rep = 1.0 / L.base_tile, detail_rep = 1.3 / L.detail_tile; // the preview's detail runs 1.3x the base's coordinates
    // A volume stacked along the Earth-centred axes at the place (up, east, north;
    // web_view.h) lines up with Atlas's noise when offset so: up by the Earth's
    // radius less `up_shift`, east and north by the map centre.
    auto stack_offset = [&](double rep, double up_shift) {
        return vec({frac((up_shift - kEquatorRadius) * rep), frac(cx * rep), frac(cy * rep)});
    };
    const render::Camera& cam = preview.job.settings.camera;
    json scene = {
        {"title", how.title},
        {"atlas", {{"layout", "three-clouds 0.7"}, {"place", "latitude 0, longitude 0; Atlas x east, y north, z up, map centre at the origin"}}},
        {"map", {{"centre", vec({cx, cy})}, {"size", vec({size_x, size_y})}}},
        {"camera", {{"position", vec({cam.position[0], cam.position[1], cam.position[2]})},
                    {"look_at", vec({cam.look_at[0], cam.look_at[1], cam.look_at[2]})},
                    {"fov", cam.fov_deg}}},
        {"sun", {{"azimuth", options.sun_azimuth}, {"elevation", options.sun_elevation}}},
        {"coverage", 0.5},
        {"layers", layers},
        {"weather", {{"repeat", vec({rep_x, rep_y})}, {"offset", vec({off_x, off_y})}}},
        {"shape", {{"repeat", vec({shape_rep, shape_rep, shape_rep})}, {"offset", stack_offset(shape_rep, evolution)}}},
        {"shape_detail", {{"repeat", vec({detail_rep, detail_rep, detail_rep})}, {"offset", stack_offset(detail_rep, 0.0)}}},
        {"turbulence", {{"repeat", vec({size_x / L.curl_tile, size_y / L.curl_tile})}, {"displacement", L.curl_amount}}},
        {"envelope", {{"min_height", w.min_height}, {"max_height", w.max_height}, {"spread", w.envelope_spread}}},
    };

    StagedOutputs out(out_dir);
    const fs::path weather_png = out.stage("local_weather.png"), turbulence_png = out.stage("turbulence.png");
    io::write_image(w.weather, weather_png);
    io::write_image(ndf::three_clouds_turbulence(*L.curl, nullptr), turbulence_png);
    const std::string shape = volume_bytes(ndf::three_clouds_shape(*L.base_noise, nullptr), kShapeSize, "shape");
    const std::string detail = volume_bytes(ndf::three_clouds_shape_detail(*L.detail_noise, nullptr), kDetailSize, "detail");
    write_file_checked(out.stage("shape.bin"), shape.data(), shape.size());
    write_file_checked(out.stage("shape_detail.bin"), detail.data(), detail.size());

    json files = scene;
    files["textures"] = {{"local_weather", "local_weather.png"}, {"shape", "shape.bin"}, {"shape_detail", "shape_detail.bin"}, {"turbulence", "turbulence.png"}};
    const std::string scene_json = files.dump(2) + "\n";
    write_file_checked(out.stage("scene.json"), scene_json.data(), scene_json.size());
    scene["textures"] = {{"local_weather", "data:image/png;base64," + base64(read_file_bytes(weather_png))},
                         {"shape", "data:application/octet-stream;base64," + base64(shape)},
                         {"shape_detail", "data:application/octet-stream;base64," + base64(detail)},
                         {"turbulence", "data:image/png;base64," + base64(read_file_bytes(turbulence_png))}};
    const std::string scene_js = "window.ATLAS_SCENE = " + scene.dump() + ";\n";
    write_file_checked(out.stage("scene.js"), scene_js.data(), scene_js.size());
    for (const char* f : kBundleFiles) fs::copy_file(how.bundle_dir / f, out.stage(f));
    out.commit();
    result.index = out_dir / "index.html";
    return result;
}

fs::path find_web_bundle(const fs::path& exe_dir) {
    std::vector<fs::path> tried;
    if (const char* env = std::getenv("ATLAS_WEB_DIR"); env && *env) {
        tried.emplace_back(env); // asked for: that one only
    } else {
        if (!exe_dir.empty()) tried.push_back(exe_dir / ".." / "share" / "atlas" / "web");
#ifdef ATLAS_WEB_DIST
        tried.emplace_back(ATLAS_WEB_DIST);
#endif
    }
    std::string where;
    for (const fs::path& d : tried) {
        if (!missing_bundle_file(d)) return d;
        where += (where.empty() ? "" : ", ") + d.string();
    }
    throw Error("atlas view: the web page is not built (looked in " + where +
                "); build it with scripts/web.sh (npm and esbuild), or set ATLAS_WEB_DIR to its dist folder");
}

} // namespace atlas::preview
