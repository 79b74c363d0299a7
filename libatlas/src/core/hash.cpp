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

// FIPS 180-4.
std::string sha256_hex(std::string_view data) {
    static const uint32_t k[64] = {
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be,
        0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa,
        0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85,
        0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3,
        0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f,
        0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};
    uint32_t h[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    auto rotr = [](uint32_t x, int n) { return (x >> n) | (x << (32 - n)); };
    auto block = [&](const unsigned char* p) {
        uint32_t w[64];
        for (int i = 0; i < 16; ++i) w[i] = uint32_t(p[4 * i]) << 24 | uint32_t(p[4 * i + 1]) << 16 | uint32_t(p[4 * i + 2]) << 8 | p[4 * i + 3];
        for (int i = 16; i < 64; ++i) {
            const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
            const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
            w[i] = w[i - 16] + s0 + w[i - 7] + s1;
        }
        uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], hh = h[7];
        for (int i = 0; i < 64; ++i) {
            const uint32_t t1 = hh + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + k[i] + w[i];
            const uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
            hh = g, g = f, f = e, e = d + t1, d = c, c = b, b = a, a = t1 + t2;
        }
        h[0] += a, h[1] += b, h[2] += c, h[3] += d, h[4] += e, h[5] += f, h[6] += g, h[7] += hh;
    };
    const uint64_t n = data.size();
    size_t i = 0;
    for (; i + 64 <= n; i += 64) block(reinterpret_cast<const unsigned char*>(data.data()) + i);
    unsigned char tail[128] = {};
    const size_t rest = size_t(n - i);
    std::copy(data.begin() + std::ptrdiff_t(i), data.end(), tail);
    tail[rest] = 0x80;
    const size_t len = rest + 9 <= 64 ? 64 : 128;
    for (int b = 0; b < 8; ++b) tail[len - 1 - size_t(b)] = static_cast<unsigned char>((n * 8) >> (8 * b));
    for (size_t o = 0; o < len; o += 64) block(tail + o);
    static const char* hex = "0123456789abcdef";
    std::string out;
    for (uint32_t v : h)
        for (int b = 28; b >= 0; b -= 4) out += hex[(v >> b) & 0xf];
    return out;
}

} // namespace atlas
