// ndf/forecast: cook an FC6 forecast into a sequence of weather maps.
#include "ndf/ndf_params.h"
#include "ndf/weather_files.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("each hour's map scrolls noise across the whole map"));
    d.doc("Far Cry 6 forecast cooked into a weather-map sequence: slice i is the map at hour start_hour + i * step_hours (regions "
          "blended at their borders, presets blended by smoothstep in time, noise scrolled with each region's wind, looping every "
          "period). `maps` is a 3D field with z = slice (write it as a DDS texture array: format dds, option array: true); "
          "`manifest` is a slices x regions table (hour, from, to, weight, drift_x, drift_y, preset fields).");
    d.output("maps", PortType::Field3D, "weather maps, z = slice (coverage, precipitation, type, cirrus_coverage)");
    d.output("manifest", PortType::Field2D, "per slice (x) and region (y): hour, presets and weight, drift, blended preset fields");
    declare_map(d);
    d.param_path("forecast").describe("forecast file (YAML, 'atlas_forecast: 1'; names its presets file), relative to the graph file");
    d.param_float("start_hour", 0).range(-1e6, 1e6).with_unit("h").describe("hour of slice 0");
    d.param_float("step_hours", 3).range(1e-3, 1e4).with_unit("h").describe("hours between slices");
    d.param_int("slices", 40).range(1, 100000).describe("number of slices (default 40 x 3 h = the 5-day loop)");
    d.param_int2("period", {{6, 6}}).range(1, 4096).with_unit("cells").describe("coverage-noise lattice cells across the map");
    d.param_int("octaves", 5).range(1, 16).describe("noise octaves");
    d.param_float("gain", 0.55).range(0, 1).describe("noise amplitude ratio between octaves");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    const ndf::Forecast f = read_forecast_file(ctx.get_path("forecast"));
    ndf::WeatherMapSpec spec;
    const int slices = int(ctx.get_int("slices"));
    spec.resolution = ctx.get_int2("resolution");
    ctx.check_memory(field_bytes(uint64_t(spec.resolution[0]) * uint64_t(spec.resolution[1]), 10) +
                         field_bytes(uint64_t(spec.resolution[0]) * uint64_t(spec.resolution[1]) * uint64_t(slices), 4),
                     "the map sequence");
    spec.bounds = map_bounds(ctx);
    spec.period = ctx.get_int2("period");
    spec.octaves = int(ctx.get_int("octaves"));
    spec.gain = ctx.get_float("gain");
    spec.seed = uint32_t(ctx.get_int("seed"));
    const double start = ctx.get_float("start_hour"), step = ctx.get_float("step_hours");
    ctx.set_output("maps", Field3DPtr(std::make_shared<const Field3D>(
                               ndf::cook_forecast(f, spec, start, step, slices, &ctx.budget(), &ctx.progress_sink()))));
    ctx.set_output("manifest", out2d(ndf::forecast_manifest_table(f, spec, start, step, slices)));
}

// The forecast reads two files: itself and the presets file it names.
void hash_extra(const NodeParams& p, Hasher& h) {
    const auto file = p.get_path("forecast");
    hash_file(h, file);
    hash_file(h, forecast_presets_file(file, read_file_bytes(file)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/forecast", .version = 2, .declare = declare, .cook = cook, .hash_extra = hash_extra});
}
