/* A host written in C (as a Unity native plugin, or a Rust or C# binding,
 * would call Atlas): load a graph, cook one field, print its size and range.
 * Usage: atlas_embed_c GRAPH NODE [PORT] */
#include "atlas/atlas.h"

#include <stdio.h>

static int on_cancel(void* user) {
    (void)user;
    return 0; /* a real host returns nonzero when the artist presses Escape */
}

int main(int argc, char** argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: atlas_embed_c GRAPH NODE [PORT]\n");
        return 2;
    }
    AtlasSession* session = NULL;
    if (atlas_session_create(&session) != ATLAS_OK) return 1;
    int rc = 1;
    AtlasField* field = NULL;
    if (atlas_session_load(session, argv[1]) != ATLAS_OK) goto fail;

    AtlasCookOptions options;
    atlas_cook_options_init(&options);
    options.cancel = on_cancel;
    if (atlas_session_get(session, argv[2], argc > 3 ? argv[3] : NULL, &options, &field) != ATLAS_OK) goto fail;

    int res[3];
    atlas_field_resolution(field, res);
    const float* data = atlas_field_channel_data(field, 0);
    float lo = data[0], hi = data[0];
    for (size_t i = 1; i < atlas_field_voxel_count(field); ++i) {
        if (data[i] < lo) lo = data[i];
        if (data[i] > hi) hi = data[i];
    }
    printf("%s: %dx%dx%d, %d channel(s), '%s' in [%g, %g]\n", argv[2], res[0], res[1], res[2],
           atlas_field_channels(field), atlas_field_channel_name(field, 0), lo, hi);
    rc = 0;
    goto done;
fail:
    fprintf(stderr, "error: %s\n", atlas_session_error(session));
done:
    atlas_field_release(field);
    atlas_session_destroy(session);
    return rc;
}
