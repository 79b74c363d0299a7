#include "atlas/core/field.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/core/memory.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <sys/mman.h>

namespace atlas {

std::vector<std::string> default_channel_names(int channels) {
    static const char* rgba[] = {"r", "g", "b", "a"};
    std::vector<std::string> names;
    for (int c = 0; c < channels; ++c) names.push_back(channels <= 4 ? rgba[c] : "c" + std::to_string(c));
    return names;
}

namespace detail {

namespace {
// Channels are zeroed and copied in fixed 1 Mi-float blocks (atlas/core/parallel.h).
constexpr size_t kFillBlock = size_t(1) << 20;

ChannelData zeroed_channel(size_t count) {
    ChannelData d(count);
    parallel_blocks(count, kFillBlock, [&](size_t i0, size_t i1) { std::memset(d.data() + i0, 0, (i1 - i0) * sizeof(float)); });
    return d;
}

ChannelData copied_channel(const float* src, size_t count) {
    ChannelData d(count);
    parallel_blocks(count, kFillBlock, [&](size_t i0, size_t i1) { std::memcpy(d.data() + i0, src + i0, (i1 - i0) * sizeof(float)); });
    return d;
}
} // namespace

namespace {
constexpr size_t kHuge = size_t(2) << 20;
// Freed large channels, kept for the next channel of the same size: a cook frees and
// makes channels of one size over and over (every 512x512x64 channel is 64 MiB), and
// a fresh one costs its page faults and the kernel's zeroing again. A miss gives every
// kept block back first, so the process never holds more than it held live at a time,
// and at most kKeptBytes are kept (a host that cooked a large graph once does not hold
// its memory for good).
constexpr size_t kKeptBytes = size_t(512) << 20;
struct FreeBlocks {
    std::mutex mutex;
    std::vector<std::pair<void*, size_t>> blocks; // pointer, rounded size
    size_t bytes = 0;
    void release_all() {
        for (auto& [p, n] : blocks) std::free(p);
        blocks.clear();
        bytes = 0;
    }
};
FreeBlocks& free_blocks() {
    // Never destroyed: a field may be freed after static destructors ran.
    static FreeBlocks* f = new FreeBlocks;
    return *f;
}
size_t rounded_size(size_t bytes) { return (bytes + kHuge - 1) / kHuge * kHuge; }
} // namespace

void* allocate_channel_bytes(size_t bytes) {
    // Channels of 8 MiB and more: transparent huge pages, aligned so whole 2 MiB pages
    // back them (the kernel decides; THP "never" ignores the advice).
    if (bytes < 4 * kHuge) {
        if (void* p = std::malloc(bytes ? bytes : 1)) return p;
        throw std::bad_alloc();
    }
    const size_t rounded = rounded_size(bytes);
    {
        FreeBlocks& f = free_blocks();
        std::lock_guard<std::mutex> lock(f.mutex);
        for (size_t i = 0; i < f.blocks.size(); ++i)
            if (f.blocks[i].second == rounded) {
                void* p = f.blocks[i].first;
                f.bytes -= rounded;
                f.blocks.erase(f.blocks.begin() + std::ptrdiff_t(i));
                return p;
            }
        f.release_all();
    }
    void* p = std::aligned_alloc(kHuge, rounded);
    if (!p) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return p;
}

void free_channel_bytes(void* p, size_t bytes) noexcept {
    if (!p) return;
    if (bytes < 4 * kHuge) return std::free(p);
    const size_t rounded = rounded_size(bytes);
    FreeBlocks& f = free_blocks();
    std::lock_guard<std::mutex> lock(f.mutex);
    if (f.bytes + rounded > kKeptBytes) return std::free(p);
    try {
        f.blocks.emplace_back(p, rounded);
        f.bytes += rounded;
    } catch (...) {
        std::free(p);
    }
}

FieldStorage::FieldStorage(const FieldStorage& o) : count_(o.count_), names_(o.names_) {
    data_.reserve(o.ptr_.size());
    for (const float* src : o.ptr_) ptr_.push_back(data_.emplace_back(copied_channel(src, o.count_)).data());
}

FieldStorage::FieldStorage(size_t count, std::vector<const float*> channels, std::vector<std::shared_ptr<const void>> owners,
                           std::vector<std::string> names)
    : count_(count), data_(channels.size()), owners_(std::move(owners)), shared_(true), names_(std::move(names)) {
    if (channels.empty() || channels.size() > 64) throw Error("field: channel count " + std::to_string(channels.size()) + " out of range (expected 1..64)");
    if (names_.size() != channels.size())
        throw Error("field: " + std::to_string(names_.size()) + " channel names given for " + std::to_string(channels.size()) + " channels");
    // Never written through: a write copies them first (own_channels).
    for (const float* c : channels) ptr_.push_back(const_cast<float*>(c));
}

void FieldStorage::own_channels() {
    for (size_t c = 0; c < ptr_.size(); ++c) {
        if (!data_[c].empty() || count_ == 0) continue;
        data_[c] = copied_channel(ptr_[c], count_);
        ptr_[c] = data_[c].data();
    }
    owners_.clear();
    shared_ = false;
}

uint64_t FieldStorage::owned_byte_size() const {
    uint64_t n = 0;
    for (const ChannelData& d : data_) n += d.size() * sizeof(float);
    return n;
}

bool FieldStorage::same_storage(const FieldStorage& o) const {
    if (names_ != o.names_ || count_ != o.count_) return false;
    for (size_t c = 0; c < ptr_.size(); ++c)
        if (!std::equal(ptr_[c], ptr_[c] + count_, o.ptr_[c])) return false;
    return true;
}

FieldStorage& FieldStorage::operator=(const FieldStorage& o) {
    if (this != &o) *this = FieldStorage(o);
    return *this;
}

FieldStorage::FieldStorage(size_t count, int channels, std::vector<std::string> names) : count_(count) {
    if (channels <= 0 || channels > 64) throw Error("field: channel count " + std::to_string(channels) + " out of range (expected 1..64)");
    if (names.empty()) names = default_channel_names(channels);
    if (names.size() != size_t(channels))
        throw Error("field: " + std::to_string(names.size()) + " channel names given for " + std::to_string(channels) + " channels");
    names_ = std::move(names);
    data_.reserve(size_t(channels));
    for (int c = 0; c < channels; ++c) {
        data_.push_back(zeroed_channel(count));
        ptr_.push_back(data_.back().data());
    }
}

int FieldStorage::find_channel(const std::string& name) const {
    for (size_t i = 0; i < names_.size(); ++i)
        if (names_[i] == name) return int(i);
    return -1;
}

void FieldStorage::set_channel_names(std::vector<std::string> names) {
    if (names.size() != ptr_.size()) throw Error("field: channel name count does not match channel count");
    names_ = std::move(names);
}

void FieldStorage::hash_storage(Hasher& h) const {
    h.add(uint64_t(ptr_.size()));
    for (size_t c = 0; c < ptr_.size(); ++c) {
        h.add(names_[c]);
        h.add_floats(std::span<const float>(ptr_[c], count_));
    }
}

} // namespace detail

namespace {
template <int N>
void check_shape(const Vec<int, N>& res, const Box<N>& bounds, const char* what) {
    for (int i = 0; i < N; ++i)
        if (res[i] <= 0) throw Error(std::string(what) + ": resolution must be positive in every axis");
    if (!bounds.valid()) throw Error(std::string(what) + ": bounds must be finite with max > min in every axis");
}

template <int N>
size_t checked_count(const Vec<int, N>& res, int channels, const MemoryBudget* budget, const char* what) {
    uint64_t n = 1;
    for (int i = 0; i < N; ++i) n *= uint64_t(res[i]);
    if (budget) {
        std::string desc = std::string("a ") + what + " of ";
        for (int i = 0; i < N; ++i) desc += (i ? "x" : "") + std::to_string(res[i]);
        desc += " voxels x " + std::to_string(channels) + " channels";
        budget->check(field_bytes(n, channels), desc);
    }
    return size_t(n);
}

// Wraps or clamps an integer index into [0, n).
inline int fix_index(int i, int n, WrapMode wrap) {
    if (wrap == WrapMode::Wrap) { i %= n; return i < 0 ? i + n : i; }
    return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

// Splits a continuous coordinate (centres at i+0.5) into the two taps and weight.
inline void taps(double u, int n, WrapMode wrap, int& i0, int& i1, float& t) {
    double f = u - 0.5;
    if (!std::isfinite(f)) f = 0.0;
    double fl = std::floor(f);
    t = float(f - fl);
    // Keep the index in int range even for absurd coordinates.
    if (fl > 1e9) fl = 1e9;
    if (fl < -1e9) fl = -1e9;
    int base = int(fl);
    i0 = fix_index(base, n, wrap);
    i1 = fix_index(base + 1, n, wrap);
}
} // namespace

Field2D::Field2D(Vec2i resolution, int channels, Box2d bounds, std::vector<std::string> channel_names, const MemoryBudget* budget)
    : FieldStorage((check_shape(resolution, bounds, "Field2D"), checked_count(resolution, channels, budget, "2D field")), channels,
                   std::move(channel_names)),
      res_(resolution), bounds_(bounds) {}

Vec2d Field2D::voxel_size() const { return {{bounds_.size()[0] / res_[0], bounds_.size()[1] / res_[1]}}; }

Vec2d Field2D::texel_center(int x, int y) const {
    Vec2d s = voxel_size();
    return {{bounds_.min[0] + (x + 0.5) * s[0], bounds_.min[1] + (y + 0.5) * s[1]}};
}

float Field2D::sample_texel(int c, double u, double v, WrapMode wrap) const {
    int x0, x1, y0, y1;
    float tx, ty;
    taps(u, res_[0], wrap, x0, x1, tx);
    taps(v, res_[1], wrap, y0, y1, ty);
    auto ch = channel(c);
    float a = lerp(ch[index(x0, y0)], ch[index(x1, y0)], tx);
    float b = lerp(ch[index(x0, y1)], ch[index(x1, y1)], tx);
    return lerp(a, b, ty);
}

float Field2D::sample_world(int c, Vec2d p, WrapMode wrap) const {
    Vec2d s = voxel_size();
    return sample_texel(c, (p[0] - bounds_.min[0]) / s[0], (p[1] - bounds_.min[1]) / s[1], wrap);
}

void Field2D::hash_into(Hasher& h) const {
    h.add("Field2D").add(res_[0]).add(res_[1]);
    for (int i = 0; i < 2; ++i) h.add(bounds_.min[i]).add(bounds_.max[i]);
    hash_storage(h);
}

Field3D::Field3D(Vec3i resolution, int channels, Box3d bounds, std::vector<std::string> channel_names, const MemoryBudget* budget)
    : FieldStorage((check_shape(resolution, bounds, "Field3D"), checked_count(resolution, channels, budget, "3D field")), channels,
                   std::move(channel_names)),
      res_(resolution), bounds_(bounds) {}

Field3D::Field3D(Vec3i resolution, Box3d bounds, std::vector<const float*> channels, std::vector<std::shared_ptr<const void>> owners,
                 std::vector<std::string> names)
    : FieldStorage(size_t(resolution[0]) * size_t(resolution[1]) * size_t(resolution[2]), std::move(channels), std::move(owners), std::move(names)),
      res_(resolution), bounds_(bounds) {}

Field3D Field3D::sharing(const std::vector<std::pair<std::shared_ptr<const Field3D>, int>>& channels, std::vector<std::string> channel_names) {
    if (channels.empty()) throw Error("Field3D::sharing: no channels given");
    const Field3D& first = *channels.front().first;
    std::vector<const float*> ptrs;
    std::vector<std::shared_ptr<const void>> owners;
    for (const auto& [f, c] : channels) {
        if (!f) throw Error("Field3D::sharing: a null field");
        if (f->resolution() != first.resolution() || !(f->bounds() == first.bounds()))
            throw Error("Field3D::sharing: the fields' grids differ (every channel must have the same resolution and bounds)");
        if (c < 0 || c >= f->channels())
            throw Error("Field3D::sharing: channel " + std::to_string(c) + " out of range (the field has " + std::to_string(f->channels()) + ")");
        ptrs.push_back(f->channel(c).data());
        if (std::find(owners.begin(), owners.end(), f) == owners.end()) owners.push_back(f);
    }
    return Field3D(first.resolution(), first.bounds(), std::move(ptrs), std::move(owners), std::move(channel_names));
}

Vec3d Field3D::voxel_size() const {
    Vec3d s = bounds_.size();
    return {{s[0] / res_[0], s[1] / res_[1], s[2] / res_[2]}};
}

Vec3d Field3D::voxel_center(int x, int y, int z) const {
    Vec3d s = voxel_size();
    return {{bounds_.min[0] + (x + 0.5) * s[0], bounds_.min[1] + (y + 0.5) * s[1], bounds_.min[2] + (z + 0.5) * s[2]}};
}

GridFrame Field3D::frame() const { return {res_, bounds_, {{0, 0, 0}}}; }

float Field3D::sample_voxel(int c, double u, double v, double w, WrapMode wrap) const {
    int x0, x1, y0, y1, z0, z1;
    float tx, ty, tz;
    taps(u, res_[0], wrap, x0, x1, tx);
    taps(v, res_[1], wrap, y0, y1, ty);
    taps(w, res_[2], wrap, z0, z1, tz);
    auto ch = channel(c);
    auto row = [&](int y, int z) { return lerp(ch[index(x0, y, z)], ch[index(x1, y, z)], tx); };
    float a = lerp(row(y0, z0), row(y1, z0), ty);
    float b = lerp(row(y0, z1), row(y1, z1), ty);
    return lerp(a, b, tz);
}

float Field3D::sample_world(int c, Vec3d p, WrapMode wrap) const {
    Vec3d s = voxel_size();
    return sample_voxel(c, (p[0] - bounds_.min[0]) / s[0], (p[1] - bounds_.min[1]) / s[1], (p[2] - bounds_.min[2]) / s[2], wrap);
}

void Field3D::hash_into(Hasher& h) const {
    h.add("Field3D").add(res_[0]).add(res_[1]).add(res_[2]);
    for (int i = 0; i < 3; ++i) h.add(bounds_.min[i]).add(bounds_.max[i]);
    hash_storage(h);
}

} // namespace atlas
