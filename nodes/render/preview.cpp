// render/preview: a Nubis³-style ray-marched picture of an NVDF set, an NDF
// set (2.5D) or both composited, so a graph can write a preview beside its
// textures (libatlas/render; the 2.5D scene and look are atlas preview's:
// atlas/render/preview.h).
#include "atlas/graph/node.h"
#include "atlas/graph/option_params.h"
#include "atlas/render/image_out.h"
#include "atlas/render/layer.h"
#include "atlas/render/preview.h"
#include "atlas/render/preview_options.h"
#include "atlas/render/renderer.h"

#include <cmath>
#include <optional>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::none("a picture of the whole scene, every ray crossing many columns: a reduction, not a field on the world grid "
                            "(preview the assembled outputs, or the tiles one by one)"));
    d.doc("Renders the NVDF set (voxel mode) and/or the NDF set (2.5D mode, the cloud layer over a curved Earth) with the "
          "preview ray-marchers (docs/render.md), as `atlas preview` does: `image` is linear radiance r, g, b plus view "
          "transmittance (write it as EXR), `preview` the tone-mapped sRGB picture (write it as PNG). Give `nvdf` "
          "(volume/nvdf's vdb_set) or `modeling` and `sdf`, and/or `ndf`; with both, the voxel clouds are composited over "
          "the layer. The parameters are `atlas preview`'s options (one schema, docs/options.md) and the picture is the "
          "library entry's that `atlas preview FILES` draws: the plain look for voxels, the 2.5D daylight look for a layer "
          "(sun_colour, sky_colour, sky_horizon 'auto'), the auto view orbiting at azimuth/elevation.");
    d.input("nvdf", PortType::Field, "4 channels dimensional_profile, detail_type, density_scale, sdf (metres)").optional = true;
    d.input("modeling", PortType::Field, "modeling NVDF (dimensional_profile, detail_type, density_scale)").optional = true;
    d.input("sdf", PortType::Field, "signed distance in metres, same grid as modeling").optional = true;
    d.input("noise", PortType::Field, "Nubis noise volume, 4 channels in [0, 1], tiling (none: no up-rez)").optional = true;
    d.input("ndf", PortType::Field2D, "2.5D: an NDF set (coverage, min_height, max_height, ...) or a weather map (coverage [, type, precipitation])")
        .optional = true;
    d.input("profile_lut", PortType::Field2D, "2.5D: ndf/profile_lut (none: the default profile)").optional = true;
    d.input("base_noise", PortType::Field3D, "2.5D: noise/hzd_set low (none: smooth shapes)").optional = true;
    d.input("detail_noise", PortType::Field3D, "2.5D: noise/hzd_set high (none: no erosion)").optional = true;
    d.input("curl", PortType::Field2D, "2.5D: noise/hzd_set curl (none: no distortion)").optional = true;
    d.input("anvil", PortType::Field2D, "2.5D: ndf/superstorm_anvil map").optional = true;
    d.input("vortex_table", PortType::Field2D, "2.5D: ndf/vortex_rings table").optional = true;
    d.input("flash_probability", PortType::Field,
            "3D field (channel 0): per-voxel relative probability of a lightning flash; each flash places flash_count lights")
        .optional = true;
    d.output("image", PortType::Field, "linear r, g, b radiance and transmittance (2D)");
    d.output("preview", PortType::Field, "tone-mapped sRGB r, g, b in [0, 1] (2D)");
    // Every parameter comes from the preview's schema, the one `atlas preview`'s
    // flags are built from (atlas/render/preview_options.h); the node's own preset: a
    // smaller picture.
    declare_text_options(d, render::preview_options(), render::preview_node_defaults());
}

void cook(CookContext& ctx) {
    render::PreviewOptions o;
    try {
        read_text_options(ctx, render::preview_options(), o);
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    std::optional<render::CloudScene> scene;
    Field3DPtr noise = ctx.has_input("noise") ? ctx.input_field3d("noise") : nullptr;
    if (ctx.has_input("nvdf")) {
        scene = render::scene_from_nvdf_set(ctx.input_field3d("nvdf"), noise, o.noise_tile);
    } else if (ctx.has_input("modeling") && ctx.has_input("sdf")) {
        scene = render::CloudScene{ctx.input_field3d("modeling"), ctx.input_field3d("sdf"), noise, o.noise_tile};
    } else if (!ctx.has_input("ndf")) {
        ctx.fail("connect 'nvdf', both 'modeling' and 'sdf', or 'ndf' (2.5D)");
    }
    std::optional<render::LayerScene> layer;
    if (ctx.has_input("ndf")) {
        // The same scene assembly as atlas preview (render::layer_preview_scene).
        render::LayerPreviewInputs in;
        in.ndf = ctx.input_field2d("ndf");
        if (!render::is_ndf_set(*in.ndf) && !render::is_weather_map(*in.ndf))
            ctx.fail("ndf: expected an NDF set (coverage, min_height, max_height) or a weather map (coverage)");
        if (ctx.has_input("profile_lut")) in.profile_lut = ctx.input_field2d("profile_lut");
        if (ctx.has_input("base_noise")) in.base_noise = ctx.input_field3d("base_noise");
        if (ctx.has_input("detail_noise")) in.detail_noise = ctx.input_field3d("detail_noise");
        if (ctx.has_input("curl")) in.curl = ctx.input_field2d("curl");
        if (ctx.has_input("anvil")) in.anvil = ctx.input_field2d("anvil");
        if (ctx.has_input("vortex_table")) in.vortex_table = ctx.input_field2d("vortex_table");
        layer = render::layer_preview_scene(in);
    }
    ctx.check_memory(uint64_t(o.size[0]) * uint64_t(o.size[1]) * 7 * sizeof(float) * (layer ? 2 : 1), "preview image");
    // The library entry atlas preview calls (render/preview.h), for given fields.
    const Field3DPtr flash = ctx.has_input("flash_probability") ? ctx.input_field3d("flash_probability") : nullptr;
    render::PreviewJob job;
    try {
        job = render::prepare_preview(std::move(scene), std::move(layer), o, render::PreviewLook::Fields, flash);
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    // Forwarded from render workers: the host's callbacks are thread-safe.
    ProgressSink sink;
    sink.on_progress = [&ctx](const ProgressEvent& e) { ctx.progress(e.fraction); };
    sink.is_cancelled = ctx.progress_sink().is_cancelled;
    render::PreviewFrame f = render::render_preview(job, &sink);
    if (f.layer_report) {
        ctx.metric("full_samples", double(f.layer_report->full_samples));
        ctx.metric("point_lights", double(f.layer_report->point_lights));
    }
    if (f.voxel_report) {
        ctx.metric("density_samples", double(f.voxel_report->density_samples));
        ctx.metric("billowy", f.voxel_report->billowy ? 1 : 0);
        ctx.metric("noise_uprez", f.voxel_report->noise_uprez ? 1 : 0);
        ctx.metric("point_lights", double(f.voxel_report->point_light_count));
    }
    auto preview = std::make_shared<Field2D>(render::tone_map(f.image, job.exposure));
    ctx.set_output("image", std::make_shared<Field2D>(std::move(f.image)));
    ctx.set_output("preview", Field2DPtr(preview));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "render/preview", .version = 3, .declare = declare, .cook = cook});
}
