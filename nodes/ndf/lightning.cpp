// ndf/lightning: a superstorm's lightning schedule over a time window, as a table.
#include "atlas/ndf/lightning.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a schedule of the whole storm"));
    d.doc("The lightning an engine plays over a superstorm (000, \"Lightning Effects\"): strike sequences of intra-cloud flashes "
          "rising in intensity, then 1 to ground_max ground discharges, in columns drawn from the NDF set's storm "
          "(superstorm_coverage, else precipitation, else coverage). Lists the flashes starting in [time, time + window): key "
          "`time` linearly with the graph's time and set `window` to a frame's length, and key `rate` to follow the storm's "
          "life. `table`: one texel per flash, channels time, duration (s), x, y, z (m), intensity, ground (0/1), sequence; "
          "write it as JSON (docs/formats.md). docs/ndf.md \"Lightning\".");
    d.input("in", PortType::Field2D, "the NDF set (its storm, min_height and max_height channels place the flashes)");
    d.output("table", PortType::Field2D, "the flashes, one texel each (write as .json)");
    const ndf::LightningOptions o;
    d.param_float("time", o.time).range(-1e9, 1e9).with_unit("s").describe("start of the window listed (key it with the graph's time)");
    d.param_float("window", o.window).range(1e-6, 86400).with_unit("s").describe("length of the window listed, e.g. one frame");
    d.param_float("rate", o.rate).range(0, 60).with_unit("1/min").describe("strike sequences per minute (key it over the storm's life)");
    d.param_int("intra_flashes", o.intra_flashes).range(0, 16).describe("intra-cloud flashes before the ground discharges");
    d.param_int("ground_max", o.ground_max).range(0, 4).describe("at most this many ground discharges per sequence (at least 1 unless 0)");
    d.param_float("spacing", o.spacing).range(1e-3, 10).with_unit("s").describe("time between a sequence's flashes");
    d.param_float("duration", o.duration).range(1e-3, 10).with_unit("s").describe("a flash's lifetime");
    d.param_float("intensity", o.intensity).range(0, 1e12).describe("a ground discharge's intensity (intra-cloud flashes rise to half)");
    d.param_int("seed", o.seed).range(0, 4294967295.0).describe("random seed");
}

void cook(CookContext& ctx) {
    const Field2DPtr set = ctx.input_field2d("in");
    ndf::LightningOptions o;
    o.time = ctx.get_float("time");
    o.window = ctx.get_float("window");
    o.rate = ctx.get_float("rate");
    o.intra_flashes = int(ctx.get_int("intra_flashes"));
    o.ground_max = int(ctx.get_int("ground_max"));
    o.spacing = ctx.get_float("spacing");
    o.duration = ctx.get_float("duration");
    o.intensity = ctx.get_float("intensity");
    o.seed = uint32_t(ctx.get_int("seed"));
    std::vector<ndf::Flash> flashes;
    try {
        flashes = ndf::lightning_schedule(*set, o);
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    ctx.metric("flashes", double(flashes.size()));
    ctx.set_output("table", out2d(ndf::lightning_table(flashes, set->bounds())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/lightning", .version = 1, .declare = declare, .cook = cook});
}
