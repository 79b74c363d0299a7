// atlas/noise/fill.h - fill field channels with tileable noise (what graph nodes call).
//
// Coordinates: voxel i of n along an axis sits at field position
// p = (i + 0.5) / n, and is looked up at lattice coordinate
// offset + frequency * p * period (see NoiseSpec). With an integer frequency
// the field holds whole tiles and wraps without a seam.
//
// Threads and determinism: work is split into fixed z-slabs (rows in 2D) on
// TBB; every sample depends only on its coordinates, and `normalize` uses an
// exact min/max, so the bytes are identical for any thread count. The calls
// are reentrant; concurrent calls must write different fields.
// Progress is reported per slab from worker threads; cancellation is polled
// per slab and throws atlas::CancelledError (the channel is then partial).
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/progress.h"
#include "atlas/noise/noise_spec.h"

#include <span>
#include <vector>

namespace atlas::noise {

// A window of a larger grid (tiled cooks, docs/scale.md): voxel (i, j, k) of
// the field filled is voxel (x0 + i, y0 + j, k) of a full_nx x full_ny grid,
// with the same value bit for bit. `normalize` needs the whole grid: an error.
struct FillWindow {
    int x0 = 0, y0 = 0, full_nx = 0, full_ny = 0;
};

// Writes noise_components(spec.kernel, 3) channels starting at `channel`.
// Throws atlas::Error on an invalid spec or when the field lacks channels.
void fill_noise(Field3D& out, int channel, const NoiseSpec& spec, const ProgressSink* progress = nullptr,
                const FillWindow* window = nullptr);

// 2D version: uses period[0..1], offset[0..1]; Curl writes 2 channels.
void fill_noise(Field2D& out, int channel, const NoiseSpec& spec, const ProgressSink* progress = nullptr,
                const FillWindow* window = nullptr);

// Point lookups (tests, sparse use). Points are field positions p in tile
// units (lattice coordinate = offset + frequency * p * period), so p and
// p + (1, 0, 0) give the same value. Returns noise_components values per
// point, interleaved. `normalize` is ignored (it needs a whole field).
// Throws atlas::Error on a non-finite point.
std::vector<float> sample_noise(const NoiseSpec& spec, std::span<const Vec3d> points);
std::vector<float> sample_noise(const NoiseSpec& spec, std::span<const Vec2d> points);

} // namespace atlas::noise
