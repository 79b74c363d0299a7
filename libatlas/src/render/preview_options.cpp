// The preview's option schema (atlas/render/preview_options.h): one table for
// `atlas preview`'s render flags and the render/preview node's parameters.
#include "atlas/render/preview_options.h"

#include "atlas/core/error.h"
#include "atlas/render/preview.h"

#include <cmath>
#include <limits>

namespace atlas::render {

bool PreviewOptions::operator==(const PreviewOptions& o) const {
    auto same_lights = [](const std::vector<PointLight>& a, const std::vector<PointLight>& b) {
        if (a.size() != b.size()) return false;
        for (size_t i = 0; i < a.size(); ++i)
            if (!(a[i].position == b[i].position && a[i].colour == b[i].colour && a[i].intensity == b[i].intensity && a[i].radius == b[i].radius))
                return false;
        return true;
    };
    return size == o.size && exposure == o.exposure && view == o.view && azimuth == o.azimuth && elevation == o.elevation &&
           manual_camera == o.manual_camera && position == o.position && look_at == o.look_at && fov == o.fov && sun_azimuth == o.sun_azimuth &&
           sun_elevation == o.sun_elevation && sun_colour == o.sun_colour && sky_colour == o.sky_colour && sky_horizon == o.sky_horizon &&
           same_lights(lights, o.lights) && lightning == o.lightning && flash_schedule == o.flash_schedule && flash_seed == o.flash_seed && flash_index == o.flash_index &&
           flash_count == o.flash_count && flash_colour == o.flash_colour && flash_intensity == o.flash_intensity && flash_radius == o.flash_radius &&
           mode == o.mode && quality == o.quality && extinction == o.extinction && noise_tile == o.noise_tile && artistic == o.artistic &&
           sky_occlusion == o.sky_occlusion &&
           ms_octaves == o.ms_octaves && ms_diffusion == o.ms_diffusion && ms_diffusion_sweeps == o.ms_diffusion_sweeps && light_grid == o.light_grid &&
           time == o.time && wind == o.wind && earth_radius == o.earth_radius &&
           edge == o.edge && envelope == o.envelope && density_units == o.density_units && sdf_skipping == o.sdf_skipping &&
           light_lookup_grid == o.light_lookup_grid && pixel_size == o.pixel_size;
}

namespace {

using K = OptionKind;
using P = PreviewOptions;
using V = OptionValue;

std::string check_lights(std::string_view text) {
    try {
        parse_point_lights(std::string(text));
        return "";
    } catch (const Error& e) {
        return e.what();
    }
}

// "N[,A,B,C[,P]]": octaves 0..16, energy, extinction, anisotropy in [0, 1], power in [0, 8].
bool ms_octave_numbers(std::string_view text, std::vector<double>& v) {
    const TextOptionSpec one{"ms_octaves", nullptr, "", K::Number, ""};
    v.clear();
    size_t start = 0;
    while (true) {
        const size_t comma = text.find(',', start);
        V x;
        if (!parse_text_option(one, text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start), x)) return false;
        v.push_back(x.number);
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    if (v.size() != 1 && v.size() != 4 && v.size() != 5) return false;
    if (v[0] != std::floor(v[0]) || v[0] < 0 || v[0] > 16) return false;
    for (size_t i = 1; i < 4 && i < v.size(); ++i)
        if (v[i] < 0 || v[i] > 1) return false;
    return v.size() < 5 || (v[4] >= 0 && v[4] <= 8);
}
std::string check_ms_octaves(std::string_view text) {
    std::vector<double> v;
    if (detail::trim_blanks(text).empty() || ms_octave_numbers(text, v)) return "";
    return "octaves N 0..16, energy A, extinction B and anisotropy C in [0, 1], scatter power P in [0, 8]";
}
// "on|off[,SWEEPS]": SWEEPS 1..4096.
bool ms_diffusion_parts(std::string_view text, bool& on, std::optional<int>& sweeps) {
    const size_t comma = text.find(',');
    const std::string_view word = detail::trim_blanks(text.substr(0, comma));
    if (word != "on" && word != "off") return false;
    on = word == "on";
    sweeps.reset();
    if (comma == std::string_view::npos) return true;
    const TextOptionSpec n{"sweeps", nullptr, "", K::Integer, "", 1, 4096};
    V x;
    if (!parse_text_option(n, text.substr(comma + 1), x)) return false;
    sweeps = int(x.number);
    return true;
}
std::string check_ms_diffusion(std::string_view text) {
    bool on = false;
    std::optional<int> sweeps;
    if (detail::trim_blanks(text).empty() || ms_diffusion_parts(text, on, sweeps)) return "";
    return "on or off, optionally ',SWEEPS' with SWEEPS 1..4096";
}

Vec3f vec3f(const V& v) { return {{float(v.numbers[0]), float(v.numbers[1]), float(v.numbers[2])}}; }
Vec3d vec3d(const V& v) { return {{v.numbers[0], v.numbers[1], v.numbers[2]}}; }
std::optional<Vec3f> colour_or_auto(const V& v) { return v.word == "auto" ? std::nullopt : std::optional<Vec3f>(vec3f(v)); }

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::vector<TextOption<P>> make_preview_options() {
    auto opt = [](TextOptionSpec spec, std::string default_text, const char* unit, void (*apply)(P&, const V&)) {
        TextOption<P> o{std::move(spec)};
        o.default_text = std::move(default_text);
        o.unit = unit;
        o.apply = apply;
        return o;
    };
    auto vec = [](TextOptionSpec spec, int count, char sep = ',') {
        spec.count = count;
        spec.separator = sep;
        return spec;
    };
    const double inf = INFINITY;
    std::vector<TextOption<P>> table = {
        opt(vec({"size", "--size", "WxH", K::Integer, "image width and height", 1, 8192}, 2, 'x'), "960x540", "px",
            [](P& p, const V& v) { p.size = {{int(v.numbers[0]), int(v.numbers[1])}}; }),
        opt({"view", nullptr, "", K::Choice,
             "camera preset: auto (a graph's clouds: ground; given fields: the orbit framing the volume or the layer orbit), orbit (azimuth, "
             "elevation), ground, aerial",
             -inf, inf, {"auto", "orbit", "ground", "aerial"}},
            "auto", "",
            [](P& p, const V& v) {
                p.view = v.word == "orbit"    ? PreviewView::Orbit
                         : v.word == "ground" ? PreviewView::Ground
                         : v.word == "aerial" ? PreviewView::Aerial
                                              : PreviewView::Auto;
            }),
        opt({"azimuth", nullptr, "", K::Number, "orbit and auto cameras: direction around the clouds (0 = from -y)", -360, 360}, "30", "deg",
            [](P& p, const V& v) { p.azimuth = v.number; }),
        opt({"elevation", nullptr, "", K::Number, "orbit and auto cameras: height angle above the clouds' centre", -89, 89}, "20", "deg",
            [](P& p, const V& v) { p.elevation = v.number; }),
        opt({"camera", nullptr, "", K::Choice, "auto: the view preset; manual: the preset with position and look_at", -inf, inf, {"auto", "manual"}},
            "auto", "", [](P& p, const V& v) { p.manual_camera = v.word == "manual"; }),
        opt(vec({"position", nullptr, "", K::Number, "manual camera position"}, 3), "0,-1000,100", "m", [](P& p, const V& v) { p.position = vec3d(v); }),
        opt(vec({"look_at", nullptr, "", K::Number, "manual camera target"}, 3), "0,0,100", "m", [](P& p, const V& v) { p.look_at = vec3d(v); }),
        opt({"fov", "--fov", "DEG", K::Number, "vertical field of view; 0 = the view's (50, ground views 60)", 0, 179}, "0", "deg",
            [](P& p, const V& v) { p.fov = v.number; }),
        opt({"sun_azimuth", nullptr, "", K::Number, "sun direction around the horizon (0 = from -y)", -360, 360}, num(kPreviewSunAzimuthDeg), "deg",
            [](P& p, const V& v) { p.sun_azimuth = v.number; }),
        opt({"sun_elevation", nullptr, "", K::Number, "sun height above the horizon", -90, 90}, num(kPreviewSunElevationDeg), "deg",
            [](P& p, const V& v) { p.sun_elevation = v.number; }),
        opt(vec({"sun_colour", "--sun-colour", "R,G,B", K::Number,
                 "linear sun radiance; auto = the look's (1,0.95,0.88; 2.6,2.45,2.25 for a 2.5D layer and a graph's voxel clouds)", 0, 1e6, {"auto"}},
                3),
            "auto", "", [](P& p, const V& v) { p.sun_colour = colour_or_auto(v); }),
        opt(vec({"sky_colour", nullptr, "", K::Number, "linear sky radiance at the zenith; auto = the look's (0.30,0.45,0.75; 0.07,0.17,0.50 daylight)",
                 0, 1e6, {"auto"}},
                3),
            "auto", "", [](P& p, const V& v) { p.sky_colour = colour_or_auto(v); }),
        opt(vec({"sky_horizon", nullptr, "", K::Number,
                 "linear sky radiance at the horizon (a gradient to sky_colour, background and ambient); auto = the look's (none: a uniform "
                 "sky; 0.45,0.55,0.70 daylight)",
                 0, 1e6, {"auto"}},
                3),
            "auto", "", [](P& p, const V& v) { p.sky_horizon = colour_or_auto(v); }),
        [] {
            TextOption<P> o{{"lights", "--light", "X,Y,Z,R,G,B,I[,RADIUS]", K::Text,
                             "point lights (metres, linear colour, inverse-square intensity, optional reach in m; commas or spaces), separated "
                             "by ';' (atlas preview: one --light per light)"}};
            o.check_text = check_lights;
            o.repeatable = true;
            o.apply = [](P& p, const V& v) { p.lights = parse_point_lights(v.text); };
            return o;
        }(),
        opt({"lightning", nullptr, "", K::Flag,
             "2.5D, without flash_probability: flash lights placed by the set's superstorm_coverage (else precipitation, coverage), 20-60 % up "
             "its columns"},
            "false", "", [](P& p, const V& v) { p.lightning = v.flag; }),
        opt({"flash_schedule", nullptr, "", K::Flag,
             "a graph that writes an ndf/lightning table: the longest strike sequence of the cooked window (a frame's) is drawn, each "
             "flash a light of flash_colour at its x, y, z with its own intensity and flash_radius"},
            "true", "", [](P& p, const V& v) { p.flash_schedule = v.flag; }),
        opt({"flash_seed", "--flash-seed", "N", K::Integer, "flash lights: seed of the position draws", 0, 4294967295.0}, "1", "",
            [](P& p, const V& v) { p.flash_seed = int64_t(v.number); }),
        opt({"flash_index", "--flash", "N", K::Integer, "flash lights: which flash (time); the same index gives the same positions", -2147483648.0,
             2147483647.0},
            "0", "", [](P& p, const V& v) { p.flash_index = int64_t(v.number); }),
        opt({"flash_count", nullptr, "", K::Integer, "flash lights: lights per flash", 0, 4096}, "1", "",
            [](P& p, const V& v) { p.flash_count = int64_t(v.number); }),
        opt(vec({"flash_colour", "--flash-colour", "R,G,B", K::Number, "flash lights: linear colour", 0, 1e6}, 3), "0.75,0.8,1", "",
            [](P& p, const V& v) { p.flash_colour = vec3f(v); }),
        opt({"flash_intensity", nullptr, "", K::Number, "flash lights: intensity of each light (inverse square, metres)", 0, 1e12}, "100000", "",
            [](P& p, const V& v) { p.flash_intensity = v.number; }),
        opt({"flash_radius", nullptr, "", K::Number, "flash lights: reach (0 = unlimited)", 0, 1e9}, "0", "m",
            [](P& p, const V& v) { p.flash_radius = v.number; }),
        opt({"mode", nullptr, "", K::Choice, "fast (SDF skipping, light grid) or reference (small fixed steps, marched light)", -inf, inf,
             {"fast", "reference"}},
            "fast", "", [](P& p, const V& v) { p.mode = v.word == "reference" ? RenderMode::Reference : RenderMode::Fast; }),
        opt({"quality", "--quality", "Q", K::Number, "fast mode: step count scale (2 = half-length steps)", 0.01, 64}, "1", "",
            [](P& p, const V& v) { p.quality = v.number; }),
        opt({"pixel_size", "--pixel-size", "N", K::Integer,
             "interactive previews: march one ray per N x N pixels and scale the picture up bilinearly (as a viewport's pixel size)", 1, 8},
            "1", "", [](P& p, const V& v) { p.pixel_size = int(v.number); }),
        opt({"extinction", "--extinction", "PER_M", K::Number, "extinction per metre at density 1", 0, 1e6}, "0.04", "1/m",
            [](P& p, const V& v) { p.extinction = v.number; }),
        opt({"exposure", "--exposure", "E", K::Number, "PNG tone map: radiance multiplier before Reinhard and sRGB", 1e-6, 1e6}, "1.5", "",
            [](P& p, const V& v) { p.exposure = v.number; }),
        opt({"noise_tile", "--noise-tile", "M", K::Number, "voxel up-rez: metres per noise period", 1e-3, 1e9}, "256", "m",
            [](P& p, const V& v) { p.noise_tile = v.number; }),
        opt({"sky_occlusion", "--sky-occlusion", "K", K::Number,
             "artistic lighting: the ambient is occluded by exp(-K x the optical depth above); 1 = Beer straight up, 0 = sqrt(1 - profile) alone "
             "(docs/render.md \"Ambient\")",
             0, 1e3},
            "0.1", "", [](P& p, const V& v) { p.sky_occlusion = v.number; }),
        opt({"artistic", "--artistic", "on|off", K::Choice,
             "off: the physical lighting a path tracer computes (no powder, octave and diffusion multiple scattering; docs/render.md \"Reference: "
             "Cycles\")",
             -inf, inf, {"on", "off"}},
            "on", "", [](P& p, const V& v) { p.artistic = v.word == "on"; }),
        [] {
            TextOption<P> o{{"ms_octaves", "--ms-octaves", "N[,A,B,C[,P]]", K::Text,
                             "with artistic off: octaves of multiple scattering (0 = single scattering; empty: " + std::to_string(kPhysicalMsOctaves) +
                                 "), optionally their energy, extinction and anisotropy factors and scatter power (defaults 0.5, 0.5 or 0.75 with the diffusion term, 0.5, 1)"}};
            o.check_text = check_ms_octaves;
            o.apply = [](P& p, const V& v) {
                if (!ms_octave_numbers(v.text, p.ms_octaves)) p.ms_octaves.clear();
            };
            return o;
        }(),
        [] {
            TextOption<P> o{{"ms_diffusion", "--ms-diffusion", "on|off[,SWEEPS]", K::Text,
                             "with artistic off: multiple scattering in thick media by diffusion on the light grid (2.5D: over a 16 km patch "
                             "of the shell and the clouds' reach past it; docs/render.md \"Multiple scattering by diffusion\"; empty: on), "
                             "optionally its SOR sweeps per level (default 32)"}};
            o.check_text = check_ms_diffusion;
            o.apply = [](P& p, const V& v) {
                bool on = false;
                if (ms_diffusion_parts(v.text, on, p.ms_diffusion_sweeps)) p.ms_diffusion = on;
                else p.ms_diffusion.reset(), p.ms_diffusion_sweeps.reset();
            };
            return o;
        }(),
        opt(vec({"light_grid", "--light-grid", "NX,NY,NZ", K::Integer, "light grid resolution (voxel: the diffusion term's grid, capped at the volume's; 2.5D with artistic off: the diffusion patch's columns and least levels)", 1, 1024}, 3),
            "128,128,32", "voxels", [](P& p, const V& v) { p.light_grid = {{int(v.numbers[0]), int(v.numbers[1]), int(v.numbers[2])}}; }),
        opt({"time", "--time", "S", K::Number, "2.5D: seconds of wind scroll (map and noise) and vortex-ring turn", -1e9, 1e9}, "0", "s",
            [](P& p, const V& v) { p.time = v.number; }),
        opt(vec({"wind", "--wind", "X,Y", K::Number, "2.5D: wind velocity (at most 1000 m/s)", -1000, 1000}, 2), "8,0", "m/s",
            [](P& p, const V& v) { p.wind = {{v.numbers[0], v.numbers[1]}}; }),
        opt({"earth_radius", "--earth-radius", "M", K::Number, "2.5D: Earth radius", 1, 1e12}, "6360000", "m",
            [](P& p, const V& v) { p.earth_radius = v.number; }),
        opt({"edge", "--edge", "auto|wrap|clamp|empty", K::Choice, "2.5D: the map beyond its bounds; auto = empty for a map with a superstorm channel, else wrap",
             -inf, inf, {"auto", "wrap", "clamp", "empty"}},
            "auto", "",
            [](P& p, const V& v) {
                p.edge = v.word == "wrap"    ? std::optional<MapEdge>(MapEdge::Wrap)
                         : v.word == "clamp" ? std::optional<MapEdge>(MapEdge::Clamp)
                         : v.word == "empty" ? std::optional<MapEdge>(MapEdge::Empty)
                                             : std::nullopt;
            }),
        opt({"envelope", "--envelope", "on|off|auto", K::Choice,
             "2.5D: skip empty space with a cone map over the cloud tops (the graph's ndf/cone_map if it writes one); auto = on above the lowest "
             "cloud base",
             -inf, inf, {"auto", "on", "off"}},
            "auto", "",
            [](P& p, const V& v) { p.envelope = v.word == "on" ? PreviewEnvelope::On : v.word == "off" ? PreviewEnvelope::Off : PreviewEnvelope::Auto; }),
        opt({"sdf_skipping", "--sdf-skipping", "on|off", K::Choice,
             "voxel: cross the SDF's empty space without sampling it (the same picture, faster); off to compare", -inf, inf, {"on", "off"}},
            "on", "", [](P& p, const V& v) { p.sdf_skipping = v.word == "on"; }),
        opt({"light_lookup", "--light-lookup", "grid|marched", K::Choice,
             "voxel: sun and sky optical depths from the light grid (fast) or marched along each light ray (as --reference does)", -inf, inf,
             {"grid", "marched"}},
            "grid", "", [](P& p, const V& v) { p.light_lookup_grid = v.word == "grid"; }),
        opt({"density_units", "--density-units", "auto|density|kg/kg", K::Choice,
             "a plain density grid's values: density (x extinction per metre), or cloud water in kg/kg (a solver's; extinction 150 x "
             "mixing ratio per metre, air 1 kg/m3, droplets 10 um); auto = kg/kg when the densest voxel is under 0.02",
             -inf, inf, {"auto", "density", "kg/kg"}},
            "auto", "",
            [](P& p, const V& v) {
                p.density_units = v.word == "density" ? DensityUnits::Density : v.word == "kg/kg" ? DensityUnits::KgPerKg : DensityUnits::Auto;
            }),
    };
    return table;
}

// Splits text at `sep` into exactly n parts (n = 0: any number of parts).
std::vector<std::string_view> split(std::string_view text, char sep) {
    std::vector<std::string_view> parts;
    size_t start = 0;
    while (true) {
        const size_t at = text.find(sep, start);
        parts.push_back(text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
        if (at == std::string_view::npos) return parts;
        start = at + 1;
    }
}
std::string join(const std::vector<std::string_view>& parts, size_t from, size_t to) {
    std::string s;
    for (size_t i = from; i < to; ++i) s += (i == from ? "" : ",") + std::string(parts[i]);
    return s;
}

} // namespace

std::span<const TextOption<PreviewOptions>> preview_options() {
    static const std::vector<TextOption<PreviewOptions>> options = make_preview_options();
    return options;
}

std::span<const OptionSpelling> preview_cli_spellings() {
    using Pairs = std::vector<std::pair<std::string, std::string>>;
    static const std::vector<OptionSpelling> spellings = {
        {"--camera", "X,Y,Z,LX,LY,LZ", "camera position and look-at point in metres (camera manual, position, look_at; default: the view's)",
         [](std::string_view t, Pairs& out) {
             const auto p = split(t, ',');
             if (p.size() != 6) return false;
             out = {{"camera", "manual"}, {"position", join(p, 0, 3)}, {"look_at", join(p, 3, 6)}};
             return true;
         }},
        {"--view", "ground|aerial|orbit[:AZ,EL]",
         "camera preset framing the clouds (view, azimuth, elevation; default: ground for a graph, the orbit framing the volume for files)",
         [](std::string_view t, Pairs& out) {
             const size_t colon = t.find(':');
             const std::string kind(t.substr(0, colon));
             if (kind != "ground" && kind != "aerial" && kind != "orbit" && kind != "auto") return false;
             out = {{"view", kind}};
             if (colon == std::string_view::npos) return true;
             const auto p = split(t.substr(colon + 1), ',');
             if (kind != "orbit" || p.size() != 2) return false;
             out.push_back({"azimuth", std::string(p[0])});
             out.push_back({"elevation", std::string(p[1])});
             return true;
         }},
        {"--sun", "AZ,EL", "sun azimuth and elevation in degrees (sun_azimuth, sun_elevation; default " + num(kPreviewSunAzimuthDeg) + "," +
                               num(kPreviewSunElevationDeg) + ")",
         [](std::string_view t, Pairs& out) {
             const auto p = split(t, ',');
             if (p.size() != 2) return false;
             out = {{"sun_azimuth", std::string(p[0])}, {"sun_elevation", std::string(p[1])}};
             return true;
         }},
        {"--sky", "ZR,ZG,ZB,HR,HG,HB", "sky gradient: zenith and horizon colours, linear (sky_colour, sky_horizon; default: the look's)",
         [](std::string_view t, Pairs& out) {
             const auto p = split(t, ',');
             if (p.size() != 6) return false;
             out = {{"sky_colour", join(p, 0, 3)}, {"sky_horizon", join(p, 3, 6)}};
             return true;
         }},
        {"--no-flash-schedule", "", "do not draw the flashes of the graph's ndf/lightning table (flash_schedule false)",
         [](std::string_view, Pairs& out) {
             out = {{"flash_schedule", "false"}};
             return true;
         }},
        {"--reference", "", "render the reference mode instead of the fast mode (mode reference)",
         [](std::string_view, Pairs& out) {
             out = {{"mode", "reference"}};
             return true;
         }},
        {"--lightning", "COUNT[,I[,RADIUS]]",
         "2.5D: COUNT flashes placed by the set's superstorm_coverage (else precipitation, coverage), intensity I (default 5e6), reach (default "
         "4000 m) (lightning, flash_count, flash_intensity, flash_radius)",
         [](std::string_view t, Pairs& out) {
             const auto p = split(t, ',');
             if (p.size() > 3) return false;
             out = {{"lightning", "true"},
                    {"flash_count", std::string(p[0])},
                    {"flash_intensity", p.size() > 1 ? std::string(p[1]) : "5e6"},
                    {"flash_radius", p.size() > 2 ? std::string(p[2]) : "4000"}};
             return true;
         }},
    };
    return spellings;
}

std::span<const std::pair<const char*, const char*>> preview_node_defaults() {
    static const std::pair<const char*, const char*> defaults[] = {{"size", "480x270"}};
    return defaults;
}

std::string preview_options_markdown() {
    auto cell = [](std::string s) {
        for (size_t i = 0; (i = s.find('|', i)) != std::string::npos; i += 2) s.replace(i, 1, "\\|");
        return s;
    };
    // The spellings that set an option, found by expanding a valid text of each.
    std::vector<std::pair<std::string, std::string>> set_by; // option -> spelling flag
    const std::pair<const char*, const char*> samples[] = {{"--camera", "1,2,3,4,5,6"}, {"--view", "orbit:30,20"},     {"--sun", "1,2"},
                                                           {"--sky", "1,1,1,1,1,1"},   {"--reference", ""},             {"--lightning", "1,2,3"}};
    for (const OptionSpelling& sp : preview_cli_spellings())
        for (const auto& [flag, text] : samples) {
            if (std::string_view(flag) != sp.cli_flag) continue;
            std::vector<std::pair<std::string, std::string>> parts;
            if (sp.expand(text, parts))
                for (const auto& part : parts) set_by.push_back({part.first, std::string(sp.cli_flag) + (*sp.metavar ? " " + std::string(sp.metavar) : "")});
        }
    std::string md = "\n## Preview options\n\n"
                     "One schema (`render::preview_options()`, atlas/render/preview_options.h) for the `atlas preview` flags and the\n"
                     "`render/preview` node's parameters: both accept exactly the same values and fill the same `render::PreviewOptions`,\n"
                     "which `render::prepare_preview` (atlas/render/preview.h) turns into the render calls of both. A flag in the\n"
                     "second column that names several options sets them all (`--sun AZ,EL` sets sun_azimuth and sun_elevation).\n"
                     "The node's defaults differ only where listed (node: ...).\n\n"
                     "| node parameter | `atlas preview` flag | accepts | default | unit | description |\n|---|---|---|---|---|---|\n";
    for (const TextOption<PreviewOptions>& o : preview_options()) {
        std::string flag = o.cli_flag ? std::string(o.cli_flag) + (*o.metavar ? " " + std::string(o.metavar) : "") : "";
        if (o.repeatable) flag += " (repeatable)";
        for (const auto& [name, by] : set_by)
            if (name == o.name && flag.find(by) == std::string::npos) flag += (flag.empty() ? "" : ", ") + by;
        std::string def = o.default_text.empty() ? "(none)" : "`" + o.default_text + "`";
        for (const auto& [name, text] : preview_node_defaults())
            if (std::string_view(name) == o.name) def += " (node: `" + std::string(text) + "`)";
        md += "| `" + std::string(o.name) + "` | " + cell(flag.empty() ? "(node only)" : "`" + flag + "`") + " | " +
              cell(o.kind == OptionKind::Flag ? "true or false" : o.expected()) + " | " + cell(def) + " | " + o.unit + " | " + cell(o.doc) + " |\n";
    }
    return md;
}

void check_preview_options(const PreviewOptions& o) {
    if (!(o.size[0] >= 1 && o.size[1] >= 1)) throw Error("preview: size must be at least 1x1 pixels");
    if (o.artistic && !o.ms_octaves.empty()) throw Error("ms_octaves sets the physical model's multiple scattering; it needs artistic off");
    if (o.artistic && o.ms_diffusion) throw Error("ms_diffusion sets the physical model's multiple scattering; it needs artistic off");
}

} // namespace atlas::render
