// atlas/core/hash.h - content hashes for caching, and coordinate hashes for
// deterministic randomness.
//
// Hash128 identifies a node output by its content (see DESIGN: hash before
// compute). Hasher is a streaming 128-bit hash; it is not cryptographic but
// mixes well enough that accidental collisions are negligible for a cache.
// All functions are pure and thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace atlas {

struct Hash128 {
    uint64_t hi = 0;
    uint64_t lo = 0;

    bool operator==(const Hash128&) const = default;
    auto operator<=>(const Hash128&) const = default;
    // 32 lowercase hex digits.
    std::string hex() const;
};

struct Hash128Hasher {
    size_t operator()(const Hash128& h) const noexcept { return static_cast<size_t>(h.lo ^ (h.hi * 0x9E3779B97F4A7C15ull)); }
};

// Streaming hasher. Every add() is length- and type-delimited so that
// ("ab","c") and ("a","bc") hash differently.
class Hasher {
public:
    Hasher& add_bytes(const void* data, size_t size);
    Hasher& add(std::string_view s);
    Hasher& add(const char* s) { return add(std::string_view(s)); }
    Hasher& add(const std::string& s) { return add(std::string_view(s)); }
    Hasher& add(uint64_t v);
    Hasher& add(int64_t v) { return add(static_cast<uint64_t>(v)); }
    Hasher& add(int v) { return add(static_cast<uint64_t>(static_cast<int64_t>(v))); }
    Hasher& add(bool v) { return add(static_cast<uint64_t>(v ? 1 : 0)); }
    // Doubles hash by bit pattern, with -0.0 folded onto 0.0.
    Hasher& add(double v);
    Hasher& add(float v) { return add(static_cast<double>(v)); }
    Hasher& add(const Hash128& h);
    Hasher& add_floats(std::span<const float> values);

    Hash128 finish() const;

private:
    void mix_word(uint64_t w);
    uint64_t a_ = 0x6A09E667F3BCC908ull;
    uint64_t b_ = 0xBB67AE8584CAA73Bull;
    uint64_t count_ = 0;
};

// splitmix64 finaliser: a bijective 64-bit mixer.
constexpr uint64_t mix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

// hash_coords as a chain of steps (seed, x, y, z, w), so a caller hashing
// neighbouring points can share the steps of their common prefix.
constexpr uint64_t hash_begin(uint32_t seed) { return mix64(seed ^ 0xA0761D6478BD642Full); }
constexpr uint64_t hash_step_x(uint64_t h, int32_t x) { return mix64(h ^ static_cast<uint32_t>(x)); }
constexpr uint64_t hash_step_y(uint64_t h, int32_t y) { return mix64(h ^ (static_cast<uint64_t>(static_cast<uint32_t>(y)) << 21)); }
constexpr uint64_t hash_step_z(uint64_t h, int32_t z) { return mix64(h ^ (static_cast<uint64_t>(static_cast<uint32_t>(z)) << 42)); }
constexpr uint32_t hash_end(uint64_t h, uint32_t w) { return static_cast<uint32_t>(mix64(h ^ w) >> 32); }

// Deterministic random bits from a seed and integer coordinates. This is the
// only source of randomness Atlas uses: results never depend on thread count,
// tile split or evaluation order.
constexpr uint32_t hash_coords(uint32_t seed, int32_t x, int32_t y = 0, int32_t z = 0, uint32_t w = 0) {
    return hash_end(hash_step_z(hash_step_y(hash_step_x(hash_begin(seed), x), y), z), w);
}

// Uniform float in [0, 1) from hash bits (24 bits of mantissa).
constexpr float hash_to_unit(uint32_t h) { return static_cast<float>(h >> 8) * (1.0f / 16777216.0f); }

// SHA-256 (FIPS 180-4) of `data`, lowercase hex: the standard hash an engine checks
// a streamed file against (the tile index records it beside the Hash128).
std::string sha256_hex(std::string_view data);

} // namespace atlas
