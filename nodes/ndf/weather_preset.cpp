// ndf/weather_preset: the weather map of one FC6 preset (or a blend of two).
#include "atlas/core/files.h"
#include "atlas/ndf/forecast.h"
#include "ndf/ndf_params.h"
#include "ndf/weather_files.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("its noise scrolls across the whole map"));
    d.doc("Far Cry 6 weather preset as a tiling weather map: channels coverage, precipitation, type, cirrus_coverage, from a presets "
          "YAML file (docs/ndf.md). Optionally blends toward a second preset; the noise scrolls with the wind for `hour` hours.");
    d.output("out", PortType::Field2D, "weather map (coverage, precipitation, type, cirrus_coverage)");
    declare_map(d);
    d.param_path("presets").describe("presets file (YAML, 'atlas_presets: 1'), relative to the graph file");
    d.param_string("preset", "").describe("preset name");
    d.param_string("blend_to", "").describe("optional second preset name ('' = none)");
    d.param_float("blend", 0).range(0, 1).describe("weight of `blend_to` (0 = `preset` exactly)");
    d.param_float("hour", 0).range(-1e6, 1e6).with_unit("h").describe("scroll time: the noise moves by wind * hour");
    d.param_int2("period", {{6, 6}}).range(1, 4096).with_unit("cells").describe("coverage-noise lattice cells across the map");
    d.param_int("octaves", 5).range(1, 16).describe("noise octaves");
    d.param_float("gain", 0.55).range(0, 1).describe("noise amplitude ratio between octaves");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    const auto presets = read_presets_file(ctx.get_path("presets"));
    const std::string& to = ctx.get_string("blend_to");
    ndf::WeatherPreset p = presets[size_t(ndf::find_preset(presets, ctx.get_string("preset")))];
    if (!to.empty()) p = ndf::lerp_presets(p, presets[size_t(ndf::find_preset(presets, to))], ctx.get_float("blend"));
    ndf::WeatherMapSpec spec;
    spec.resolution = map_resolution(ctx, 6);
    spec.bounds = map_bounds(ctx);
    spec.period = ctx.get_int2("period");
    spec.octaves = int(ctx.get_int("octaves"));
    spec.gain = ctx.get_float("gain");
    spec.seed = uint32_t(ctx.get_int("seed"));
    const Field2D noise = ndf::make_weather_noise(spec, &ctx.budget());
    const Vec2d drift = ndf::wind_velocity(p) * (ctx.get_float("hour") * 3600.0);
    ctx.set_output("out", out2d(ndf::preset_weather_map(p, noise, drift, &ctx.budget())));
}

void hash_extra(const NodeParams& p, Hasher& h) { hash_file(h, p.get_path("presets")); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/weather_preset", .version = 1, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
