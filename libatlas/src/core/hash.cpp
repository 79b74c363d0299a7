#include "atlas/core/hash.h"

#include <bit>
#include <cstring>

namespace atlas {

std::string Hash128::hex() const {
    static const char* digits = "0123456789abcdef";
    std::string s(32, '0');
    for (int i = 0; i < 16; ++i) {
        s[size_t(15 - i)] = digits[(hi >> (4 * i)) & 15];
        s[size_t(31 - i)] = digits[(lo >> (4 * i)) & 15];
    }
    return s;
}

// Two independent 64-bit lanes, each absorbing words through a bijective
// mixer; different constants and cross-feeding make the lanes decorrelated.
void Hasher::mix_word(uint64_t w) {
    a_ = mix64(a_ ^ w) + 0x2545F4914F6CDD1Dull;
    b_ = mix64(b_ + (w ^ 0xD6E8FEB86659FD93ull)) ^ (a_ >> 17);
    ++count_;
}

Hasher& Hasher::add_bytes(const void* data, size_t size) {
    mix_word(0xB10B5ull ^ size);
    const auto* p = static_cast<const unsigned char*>(data);
    size_t i = 0;
    for (; i + 8 <= size; i += 8) {
        uint64_t w;
        std::memcpy(&w, p + i, 8);
        mix_word(w);
    }
    if (i < size) {
        uint64_t w = 0;
        std::memcpy(&w, p + i, size - i);
        mix_word(w ^ (uint64_t(size - i) << 56));
    }
    return *this;
}

Hasher& Hasher::add(std::string_view s) { return add_bytes(s.data(), s.size()); }

Hasher& Hasher::add(uint64_t v) {
    mix_word(0x1A7ull);
    mix_word(v);
    return *this;
}

Hasher& Hasher::add(double v) {
    if (v == 0.0) v = 0.0; // fold -0.0 onto +0.0
    mix_word(0xF10A7ull);
    mix_word(std::bit_cast<uint64_t>(v));
    return *this;
}

Hasher& Hasher::add(const Hash128& h) {
    mix_word(0x4A54ull);
    mix_word(h.hi);
    mix_word(h.lo);
    return *this;
}

Hasher& Hasher::add_floats(std::span<const float> values) { return add_bytes(values.data(), values.size_bytes()); }

Hash128 Hasher::finish() const {
    uint64_t a = mix64(a_ ^ count_);
    uint64_t b = mix64(b_ ^ (count_ * 0x9E3779B97F4A7C15ull));
    return {mix64(a ^ (b << 1)), mix64(b ^ (a >> 1) ^ 0x5851F42D4C957F2Dull)};
}

} // namespace atlas
