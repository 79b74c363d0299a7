// atlas/core/field.h - dense 2D and 3D grids of float channels over a world box.
//
// Layout: channel-planar. channel(c)[index(x, y, z)] with x fastest, then y,
// then z. Samples are cell-centred: voxel (i, j, k) covers
// [min + i*voxel, min + (i+1)*voxel) and its value sits at the cell centre.
// Fields are values: nodes produce them and never mutate a field they were
// given (they are shared as std::shared_ptr<const Field3D>).
// A const Field is safe to read from any number of threads.
#pragma once

#include "atlas/core/math.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace atlas {

class Hasher;
class MemoryBudget;
struct GridFrame;

// How sampling treats coordinates outside the grid.
enum class WrapMode {
    Clamp, // repeat the edge sample
    Wrap,  // periodic: the grid tiles (used by tileable noise)
};

namespace detail {
void* allocate_channel_bytes(size_t bytes);
void free_channel_bytes(void* p, size_t bytes) noexcept;
// Allocator that leaves floats uninitialised on resize, so FieldStorage can
// zero and copy channels in parallel (first touch of hundreds of MB is the
// dominant cost of a large field on a VM; see docs/DECISIONS.md). Large
// channels are asked for transparent huge pages: a 512x512x64 channel touched
// in 4 KiB pages took ~16k page faults, the cook's largest system-time cost
// (issue 49); small ones come from the heap as before.
template <typename T>
struct UninitialisedAllocator : std::allocator<T> {
    template <typename U>
    struct rebind {
        using other = UninitialisedAllocator<U>;
    };
    UninitialisedAllocator() = default;
    template <typename U>
    UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
    template <typename U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U; // default-init: no write
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    T* allocate(size_t n) { return static_cast<T*>(allocate_channel_bytes(n * sizeof(T))); }
    void deallocate(T* p, size_t n) noexcept { free_channel_bytes(p, n * sizeof(T)); }
};
using ChannelData = std::vector<float, UninitialisedAllocator<float>>;

// Shared by Field2D and Field3D: channels, names, storage.
class FieldStorage {
public:
    int channels() const { return static_cast<int>(ptr_.size()); }
    const std::vector<std::string>& channel_names() const { return names_; }
    const std::string& channel_name(int c) const { return names_[static_cast<size_t>(c)]; }
    // Index of a named channel, or -1.
    int find_channel(const std::string& name) const;
    // Writing to a field that shares channels copies them first (own_channels).
    std::span<float> channel(int c) {
        if (shared_) [[unlikely]]
            own_channels();
        return {ptr_[static_cast<size_t>(c)], count_};
    }
    std::span<const float> channel(int c) const { return {ptr_[static_cast<size_t>(c)], count_}; }
    size_t voxel_count() const { return count_; }
    // Bytes of the field's channels as a value (shared channels counted too).
    uint64_t byte_size() const { return uint64_t(count_) * ptr_.size() * sizeof(float); }
    // Bytes this field allocated itself (shared channels belong to their owners).
    uint64_t owned_byte_size() const;
    void set_channel_names(std::vector<std::string> names);

protected:
    FieldStorage(size_t count, int channels, std::vector<std::string> names);
    // Channels of other fields, shared without a copy: `owners` keep them alive.
    FieldStorage(size_t count, std::vector<const float*> channels, std::vector<std::shared_ptr<const void>> owners,
                 std::vector<std::string> names);
    // Copies fill the new channels in parallel (same bytes as a serial copy); a copy owns its channels.
    FieldStorage(const FieldStorage& o);
    FieldStorage& operator=(const FieldStorage& o);
    // Moving keeps every channel's address (the vectors' buffers move with them).
    FieldStorage(FieldStorage&&) noexcept = default;
    FieldStorage& operator=(FieldStorage&&) noexcept = default;
    ~FieldStorage() = default;
    void hash_storage(Hasher& h) const;
    bool same_storage(const FieldStorage& o) const;
    void own_channels();

    size_t count_ = 0;
    std::vector<ChannelData> data_;  // the channels this field owns (empty where shared)
    std::vector<float*> ptr_;        // every channel's samples
    std::vector<std::shared_ptr<const void>> owners_; // keep shared channels alive
    bool shared_ = false;
    std::vector<std::string> names_;
};
} // namespace detail

// Bytes a field of this many voxels and channels needs (for budget checks).
constexpr uint64_t field_bytes(uint64_t voxels, int channels) { return voxels * uint64_t(channels) * sizeof(float); }

class Field2D : public detail::FieldStorage {
public:
    // Zero-filled field. Throws atlas::Error on a non-positive resolution,
    // channel count or an invalid box; checks `budget` when given.
    Field2D(Vec2i resolution, int channels, Box2d bounds, std::vector<std::string> channel_names = {},
            const MemoryBudget* budget = nullptr);

    Vec2i resolution() const { return res_; }
    int width() const { return res_[0]; }
    int height() const { return res_[1]; }
    const Box2d& bounds() const { return bounds_; }
    Vec2d voxel_size() const;
    size_t index(int x, int y) const { return size_t(y) * size_t(res_[0]) + size_t(x); }
    float at(int c, int x, int y) const { return channel(c)[index(x, y)]; }
    float& at(int c, int x, int y) { return channel(c)[index(x, y)]; }

    // World position of the centre of texel (x, y).
    Vec2d texel_center(int x, int y) const;
    // Bilinear sample at continuous texel coordinates (texel centres at i+0.5).
    float sample_texel(int c, double u, double v, WrapMode wrap) const;
    // Bilinear sample at a world position.
    float sample_world(int c, Vec2d p, WrapMode wrap) const;

    void hash_into(Hasher& h) const;
    bool operator==(const Field2D& o) const { return res_ == o.res_ && bounds_ == o.bounds_ && same_storage(o); }

private:
    Vec2i res_;
    Box2d bounds_;
};

class Field3D : public detail::FieldStorage {
public:
    Field3D(Vec3i resolution, int channels, Box3d bounds, std::vector<std::string> channel_names = {},
            const MemoryBudget* budget = nullptr);
    // A field made of other fields' channels (field, channel index), shared
    // without a copy: the NVDF node's VDB set is its modeling channels and the
    // SDF. Every source must have the same resolution and bounds; a write to the
    // result copies its channels first, so the sources never change.
    static Field3D sharing(const std::vector<std::pair<std::shared_ptr<const Field3D>, int>>& channels, std::vector<std::string> channel_names);

    Vec3i resolution() const { return res_; }
    int nx() const { return res_[0]; }
    int ny() const { return res_[1]; }
    int nz() const { return res_[2]; }
    const Box3d& bounds() const { return bounds_; }
    Vec3d voxel_size() const;
    size_t index(int x, int y, int z) const { return (size_t(z) * size_t(res_[1]) + size_t(y)) * size_t(res_[0]) + size_t(x); }
    float at(int c, int x, int y, int z) const { return channel(c)[index(x, y, z)]; }
    float& at(int c, int x, int y, int z) { return channel(c)[index(x, y, z)]; }

    Vec3d voxel_center(int x, int y, int z) const;
    GridFrame frame() const;
    // Trilinear sample at continuous voxel coordinates (voxel centres at i+0.5).
    float sample_voxel(int c, double u, double v, double w, WrapMode wrap) const;
    // Trilinear sample at a world position.
    float sample_world(int c, Vec3d p, WrapMode wrap) const;

    void hash_into(Hasher& h) const;
    bool operator==(const Field3D& o) const { return res_ == o.res_ && bounds_ == o.bounds_ && same_storage(o); }

private:
    Field3D(Vec3i resolution, Box3d bounds, std::vector<const float*> channels, std::vector<std::shared_ptr<const void>> owners,
            std::vector<std::string> names);
    Vec3i res_;
    Box3d bounds_;
};

using Field2DPtr = std::shared_ptr<const Field2D>;
using Field3DPtr = std::shared_ptr<const Field3D>;

// Voxels [x0, x1) x [y0, y1), all of z, of a grid: the part of it a tiled
// cook asks a generator for (graph's TileWindow, without the grid).
struct XYWindow {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    // Texel edge i of n between lo and hi (exactly lo at 0, hi at n): the one
    // formula for the bounds of every tile, crop and window.
    static double edge(double lo, double hi, int i, int n) {
        if (i <= 0) return lo;
        if (i >= n) return hi;
        return lo + (hi - lo) * double(i) / double(n);
    }
    // The window's bounds in a grid of `res` voxels over `b` (z whole).
    Box3d bounds(Vec3i res, const Box3d& b) const {
        return {{{edge(b.min[0], b.max[0], x0, res[0]), edge(b.min[1], b.max[1], y0, res[1]), b.min[2]}},
                {{edge(b.min[0], b.max[0], x1, res[0]), edge(b.min[1], b.max[1], y1, res[1]), b.max[2]}}};
    }
};

// Where a field's voxels sit in a grid it may be a window of: the whole
// grid's resolution and bounds and the window's first voxel. A tiled cook
// hands a node a crop of the world grid; positions computed through the
// frame are the whole grid's to the last bit (a crop's own bounds are not),
// so the tile's values are the untiled cook's. Field3D::frame() is a field's
// own frame (offset 0): the same numbers as Field3D::voxel_center.
struct GridFrame {
    Vec3i res{{1, 1, 1}}; // the whole grid
    Box3d bounds;         // the whole grid
    Vec3i offset{{0, 0, 0}};
    Vec3d voxel_size() const {
        const Vec3d s = bounds.size();
        return {{s[0] / res[0], s[1] / res[1], s[2] / res[2]}};
    }
    // Centre of the window's voxel (x, y, z): Field3D::voxel_center's arithmetic on the whole grid.
    Vec3d voxel_center(int x, int y, int z) const {
        const Vec3d s = voxel_size();
        return {{bounds.min[0] + ((x + offset[0]) + 0.5) * s[0], bounds.min[1] + ((y + offset[1]) + 0.5) * s[1],
                 bounds.min[2] + ((z + offset[2]) + 0.5) * s[2]}};
    }
    // The field is the whole grid, or the same window of it.
    bool same_grid(const Field3D& f) const { return f.resolution() == res && f.bounds() == bounds; }
};

// Default channel names: "r", "g", "b", "a" for up to 4 channels, else "c0".. .
std::vector<std::string> default_channel_names(int channels);

} // namespace atlas
