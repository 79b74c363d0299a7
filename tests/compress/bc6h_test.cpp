// BC6H: the decoder against hand-worked blocks built bit by bit from the D3D11 layout
// table, and the encoder's properties (bounds, round trips, adversarial blocks).
#include "atlas/compress/bc6h.h"
#include "atlas/compress/texture.h"
#include "atlas/io/dds_file.h"
#include "atlas/core/error.h"

#include "test_blocks.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

namespace atlas::compress {
namespace fs = std::filesystem;
using io::compress_to_dds;
using io::read_dds;
using io::read_dds_file;
using io::verify_dds;
namespace {

// ---------------------------------------------------------------------------------
// An independent block writer: the endpoint layout of every mode as printed in the
// D3D11 "BC6H compressed endpoint format" table ("name[hi:lo]" = bits lo..hi stored
// LSB first; the two one-region modes that store high bits in reverse order are
// spelled bit by bit, highest first, as the table's reversed ranges mean).
struct SpecMode {
    const char* mode_bits; // m[4:0] (or m[1:0]) as printed, most significant first
    const char* layout;
    bool two_regions;
};
const std::map<int, SpecMode> kSpec = {
    {1, {"00", "gy[4] by[4] bz[4] rw[9:0] gw[9:0] bw[9:0] rx[4:0] gz[4] gy[3:0] gx[4:0] bz[0] gz[3:0] bx[4:0] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]", true}},
    {2, {"01", "gy[5] gz[4] gz[5] rw[6:0] bz[0] bz[1] by[4] gw[6:0] by[5] bz[2] gy[4] bw[6:0] bz[3] bz[5] bz[4] rx[5:0] gy[3:0] gx[5:0] gz[3:0] bx[5:0] by[3:0] ry[5:0] rz[5:0] d[4:0]", true}},
    {3, {"00010", "rw[9:0] gw[9:0] bw[9:0] rx[4:0] rw[10] gy[3:0] gx[3:0] gw[10] bz[0] gz[3:0] bx[3:0] bw[10] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]", true}},
    {4, {"00110", "rw[9:0] gw[9:0] bw[9:0] rx[3:0] rw[10] gz[4] gy[3:0] gx[4:0] gw[10] gz[3:0] bx[3:0] bw[10] bz[1] by[3:0] ry[3:0] bz[0] bz[2] rz[3:0] gy[4] bz[3] d[4:0]", true}},
    {5, {"01010", "rw[9:0] gw[9:0] bw[9:0] rx[3:0] rw[10] by[4] gy[3:0] gx[3:0] gw[10] bz[0] gz[3:0] bx[4:0] bw[10] by[3:0] ry[3:0] bz[1] bz[2] rz[3:0] bz[4] bz[3] d[4:0]", true}},
    {6, {"01110", "rw[8:0] by[4] gw[8:0] gy[4] bw[8:0] bz[4] rx[4:0] gz[4] gy[3:0] gx[4:0] bz[0] gz[3:0] bx[4:0] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]", true}},
    {7, {"10010", "rw[7:0] gz[4] by[4] gw[7:0] bz[2] gy[4] bw[7:0] bz[3] bz[4] rx[5:0] gy[3:0] gx[4:0] bz[0] gz[3:0] bx[4:0] bz[1] by[3:0] ry[5:0] rz[5:0] d[4:0]", true}},
    {8, {"10110", "rw[7:0] bz[0] by[4] gw[7:0] gy[5] gy[4] bw[7:0] gz[5] bz[4] rx[4:0] gz[4] gy[3:0] gx[5:0] gz[3:0] bx[4:0] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]", true}},
    {9, {"11010", "rw[7:0] bz[1] by[4] gw[7:0] by[5] gy[4] bw[7:0] bz[5] bz[4] rx[4:0] gz[4] gy[3:0] gx[4:0] bz[0] gz[3:0] bx[5:0] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]", true}},
    {10, {"11110", "rw[5:0] gz[4] bz[0] bz[1] by[4] gw[5:0] gy[5] by[5] bz[2] gy[4] bw[5:0] gz[5] bz[3] bz[5] bz[4] rx[5:0] gy[3:0] gx[5:0] gz[3:0] bx[5:0] by[3:0] ry[5:0] rz[5:0] d[4:0]", true}},
    {11, {"00011", "rw[9:0] gw[9:0] bw[9:0] rx[9:0] gx[9:0] bx[9:0]", false}},
    {12, {"00111", "rw[9:0] gw[9:0] bw[9:0] rx[8:0] rw[10] gx[8:0] gw[10] bx[8:0] bw[10]", false}},
    {13, {"01011", "rw[9:0] gw[9:0] bw[9:0] rx[7:0] rw[11] rw[10] gx[7:0] gw[11] gw[10] bx[7:0] bw[11] bw[10]", false}},
    {14, {"01111", "rw[9:0] gw[9:0] bw[9:0] rx[3:0] rw[15] rw[14] rw[13] rw[12] rw[11] rw[10] gx[3:0] gw[15] gw[14] gw[13] gw[12] gw[11] gw[10] bx[3:0] bw[15] bw[14] bw[13] bw[12] bw[11] bw[10]", false}},
};
// Second-region anchor texels of the 32 shapes (spec "fix-up index" table) and the shapes.
const int kTestAnchor[32] = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                             15, 2, 8, 2, 2, 8, 8, 15, 2, 8, 2, 2, 8, 8, 2, 2};

struct TestBits {
    uint8_t b[16] = {};
    int pos = 0;
    void put(int bit) {
        if (bit) b[pos / 8] = uint8_t(b[pos / 8] | (1 << (pos % 8)));
        ++pos;
    }
};

// Builds a block from named field values (raw stored values: deltas as stored) and indices.
std::vector<uint8_t> build_block(int mode, const std::map<std::string, int>& fields, int partition, const std::vector<int>& idx) {
    const SpecMode& s = kSpec.at(mode);
    TestBits w;
    const std::string mb = s.mode_bits;
    for (size_t i = 0; i < mb.size(); ++i) w.put(mb[mb.size() - 1 - i] == '1'); // LSB first
    std::istringstream in(s.layout);
    std::string tok;
    while (in >> tok) {
        const std::string name = tok.substr(0, tok.find('['));
        const std::string range = tok.substr(tok.find('[') + 1, tok.size() - tok.find('[') - 2);
        int hi, lo;
        if (range.find(':') != std::string::npos) { hi = std::stoi(range.substr(0, range.find(':'))); lo = std::stoi(range.substr(range.find(':') + 1)); }
        else hi = lo = std::stoi(range);
        const int v = name == "d" ? partition : (fields.count(name) ? fields.at(name) : 0);
        for (int bit = lo; bit <= hi; ++bit) w.put((v >> bit) & 1);
    }
    EXPECT_EQ(w.pos, s.two_regions ? 82 : 65) << "mode " << mode << " header + endpoints";
    for (int t = 0; t < 16; ++t) {
        int bits = s.two_regions ? 3 : 4;
        if (t == 0 || (s.two_regions && t == kTestAnchor[partition])) --bits;
        for (int k = 0; k < bits; ++k) w.put((idx[size_t(t)] >> k) & 1);
    }
    EXPECT_EQ(w.pos, 128);
    return std::vector<uint8_t>(w.b, w.b + 16);
}

// A fully hand-worked block: mode 11 (10-bit endpoints stored directly), UF16.
//   red   rw = 0,   rx = 1023: unquantize 0 -> 0, 1023 (all ones) -> 0xFFFF
//   green rw = 512, rx = 512:  ((512 << 16) + 0x8000) >> 10 = 32800 for both
//   blue  rw = 1,   rx = 2:    (65536 + 32768) >> 10 = 96, (131072 + 32768) >> 10 = 160
// indices: texel 0 -> 0, texel 1 -> 15 (weight 64), texel 2 -> 8 (weight 34), rest 0.
//   texel 0: r 0 -> 0; g 32800 * 31 >> 6 = 15887 (0x3E0F); b 96 * 31 >> 6 = 46
//   texel 1: r (65535 * 64 + 32) >> 6 = 65535 -> 65535 * 31 >> 6 = 31743 (0x7BFF = 65504.0);
//            g 15887; b 160 -> 160 * 31 >> 6 = 77
//   texel 2: r (65535 * 34 + 32) >> 6 = 34815 -> 34815 * 31 >> 6 = 16863 (0x41DF);
//            g (32800 * 64 + 32) >> 6 = 32800 -> 15887; b (96 * 30 + 160 * 34 + 32) >> 6 = 130 -> 62
TEST(Bc6hDecode, HandWorkedMode11) {
    std::vector<int> idx(16, 0);
    idx[1] = 15;
    idx[2] = 8;
    const auto blk = build_block(11, {{"rw", 0}, {"rx", 1023}, {"gw", 512}, {"gx", 512}, {"bw", 1}, {"bx", 2}}, 0, idx);
    EXPECT_EQ(bc6h_block_mode(blk.data()), 11);
    uint16_t h[48];
    decode_bc6h_block_half(blk.data(), false, h);
    const uint16_t expect[9] = {0, 15887, 46, 31743, 15887, 77, 16863, 15887, 62};
    for (int i = 0; i < 9; ++i) EXPECT_EQ(h[i], expect[i]) << i;
    for (int t = 3; t < 16; ++t) EXPECT_EQ(h[3 * t], 0);
    float f[48];
    decode_bc6h_block(blk.data(), false, f);
    EXPECT_EQ(f[3], 65504.0f);
    EXPECT_EQ(f[0], 0.0f);
}

// Hand-worked sign handling: mode 14 (16-bit endpoint, 4-bit deltas), SF16.
//   red rw = 0xFFF0 (bits 15..10 stored reversed) = -16 as 16-bit two's complement;
//   rx = 0b1000 -> sign-extended delta -8 -> endpoint -24. No unquantize at 16 bits.
//   texel 0 (index 0): -16 -> magnitude (16 * 31) >> 5 = 15 -> 0x800F
//   texel 1 (index 15, weight 64): (-24 * 64 + 32) >> 6 = -24 (arithmetic shift: -1504 >> 6 = -24)
//            -> magnitude 24 * 31 >> 5 = 23 -> 0x8017
//   green gw = 0x7FFF, gx = 0b0111 (+7): (0x7FFF + 7) & 0xFFFF = 0x8006 -> sign-extended -32762
//   (the transform wraps): texel 1 magnitude 32762 * 31 >> 5 = 31738 -> 0xFBFA; texel 0 0x7FFF * 31 >> 5 = 31743 = 0x7BFF
TEST(Bc6hDecode, HandWorkedMode14Signed) {
    std::vector<int> idx(16, 0);
    idx[1] = 15;
    const auto blk = build_block(14, {{"rw", 0xFFF0}, {"rx", 8}, {"gw", 0x7FFF}, {"gx", 7}, {"bw", 0}, {"bx", 0}}, 0, idx);
    uint16_t h[48];
    decode_bc6h_block_half(blk.data(), true, h);
    EXPECT_EQ(h[0], 0x800F);
    EXPECT_EQ(h[3], 0x8017);
    EXPECT_EQ(h[1], 0x7BFF);
    EXPECT_EQ(h[4], 0xFBFA);
    EXPECT_EQ(h[2], 0);
    EXPECT_EQ(h[5], 0);
}

// Every mode, UF16 and SF16: all fields set to mixed bit patterns, every texel checked.
// The expected halves were computed by a separate script from the spec's arithmetic only
// (sign extension, inverse transform, unquantize, interpolation, finish_unquantize); the
// comment above each row shows its endpoints and unquantized values.
struct Vector {
    int mode;
    bool is_signed;
    std::map<std::string, int> fields;
    int partition;
    std::vector<int> idx;
    std::vector<uint16_t> halves;
};
const std::vector<Vector> kVectors = {
    // mode 1 UF16: endpoints (after transform) [[44, 569, 238], [59, 574, 245], [36, 567, 247], [57, 563, 237]]; unquantized [[2848, 36448, 15264], [3808, 36768, 15712], [2336, 36320, 15840], [3680, 36064, 15200]]
    {1, false, {{"rw", 44}, {"rx", 15}, {"ry", 24}, {"rz", 13}, {"gw", 569}, {"gx", 5}, {"gy", 30}, {"gz", 26}, {"bw", 238}, {"bx", 7}, {"by", 9}, {"bz", 31}}, 7, {1, 4, 2, 3, 6, 5, 0, 6, 0, 1, 4, 1, 4, 1, 5, 0},
     {0x05A4, 0x450C, 0x1D00, 0x0670, 0x4550, 0x1D5E, 0x05E6, 0x4522, 0x1D1E, 0x0627, 0x4537, 0x1D3D, 0x06F3, 0x457B, 0x1D9B, 0x06B1, 0x4565, 0x1D7D, 0x0563, 0x44F6, 0x1CE1, 0x069A, 0x444D, 0x1CEE, 0x0563, 0x44F6, 0x1CE1, 0x05A4, 0x450C, 0x1D00, 0x05E3, 0x4470, 0x1D45, 0x04C7, 0x44A7, 0x1DCC, 0x0670, 0x4550, 0x1D5E, 0x04C7, 0x44A7, 0x1DCC, 0x063F, 0x445F, 0x1D19, 0x046B, 0x44B8, 0x1DF8}},
    // mode 2 UF16: endpoints (after transform) [[49, 87, 79], [53, 90, 68], [45, 88, 65], [47, 62, 63]]; unquantized [[25344, 44800, 40704], [27392, 46336, 35072], [23296, 45312, 33536], [24320, 32000, 32512]]
    {2, false, {{"rw", 49}, {"rx", 4}, {"ry", 60}, {"rz", 62}, {"gw", 87}, {"gx", 3}, {"gy", 1}, {"gz", 39}, {"bw", 79}, {"bx", 53}, {"by", 50}, {"bz", 48}}, 14, {1, 3, 2, 1, 4, 4, 7, 1, 1, 1, 1, 0, 7, 1, 1, 3},
     {0x307F, 0x552C, 0x4B84, 0x3196, 0x55FD, 0x4885, 0x310B, 0x5595, 0x4A04, 0x307F, 0x552C, 0x4B84, 0x2D32, 0x472C, 0x3E55, 0x2D32, 0x472C, 0x3E55, 0x2E04, 0x3C8C, 0x3D84, 0x2C59, 0x5231, 0x3F2E, 0x2C59, 0x5231, 0x3F2E, 0x2C59, 0x5231, 0x3F2E, 0x2C59, 0x5231, 0x3F2E, 0x2C14, 0x55BC, 0x3F74, 0x2E04, 0x3C8C, 0x3D84, 0x2C59, 0x5231, 0x3F2E, 0x2C59, 0x5231, 0x3F2E, 0x2CE5, 0x4B1B, 0x3EA2}},
    // mode 3 UF16: endpoints (after transform) [[1206, 399, 1762], [1203, 395, 1769], [1204, 392, 1755], [1203, 394, 1763]]; unquantized [[38608, 12784, 56400], [38512, 12656, 56624], [38544, 12560, 56176], [38512, 12624, 56432]]
    {3, false, {{"rw", 1206}, {"rx", 29}, {"ry", 30}, {"rz", 29}, {"gw", 399}, {"gx", 12}, {"gy", 9}, {"gz", 11}, {"bw", 1762}, {"bx", 7}, {"by", 9}, {"bz", 1}}, 21, {2, 5, 7, 6, 4, 7, 3, 2, 3, 4, 3, 6, 3, 5, 2, 2},
     {0x48FF, 0x181E, 0x6AD5, 0x48EB, 0x1803, 0x6B04, 0x48DE, 0x17F2, 0x6B23, 0x48E5, 0x17FA, 0x6B14, 0x48E5, 0x17D5, 0x6A91, 0x48DE, 0x17F2, 0x6B23, 0x48F9, 0x1816, 0x6AE4, 0x48FF, 0x181E, 0x6AD5, 0x48E7, 0x17D0, 0x6A7E, 0x48E5, 0x17D5, 0x6A91, 0x48F9, 0x1816, 0x6AE4, 0x48E5, 0x17FA, 0x6B14, 0x48E7, 0x17D0, 0x6A7E, 0x48E2, 0x17DA, 0x6AA3, 0x48E9, 0x17CC, 0x6A6D, 0x48FF, 0x181E, 0x6AD5}},
    // mode 4 UF16: endpoints (after transform) [[613, 1801, 1614], [614, 1794, 1618], [619, 1816, 1620], [618, 1800, 1607]]; unquantized [[19632, 57648, 51664], [19664, 57424, 51792], [19824, 58128, 51856], [19792, 57616, 51440]]
    {4, false, {{"rw", 613}, {"rx", 1}, {"ry", 6}, {"rz", 5}, {"gw", 1801}, {"gx", 25}, {"gy", 15}, {"gz", 31}, {"bw", 1614}, {"bx", 4}, {"by", 6}, {"bz", 9}}, 28, {1, 2, 2, 3, 5, 5, 4, 4, 2, 2, 3, 4, 2, 4, 0, 4},
     {0x2527, 0x6D04, 0x61C9, 0x2529, 0x6CF4, 0x61D2, 0x2529, 0x6CF4, 0x61D2, 0x257B, 0x6D93, 0x61C8, 0x2530, 0x6CC5, 0x61ED, 0x2577, 0x6D49, 0x618C, 0x2579, 0x6D6C, 0x61A9, 0x2579, 0x6D6C, 0x61A9, 0x257D, 0x6DB6, 0x61E5, 0x257D, 0x6DB6, 0x61E5, 0x257B, 0x6D93, 0x61C8, 0x252E, 0x6CD4, 0x61E4, 0x257D, 0x6DB6, 0x61E5, 0x252E, 0x6CD4, 0x61E4, 0x2525, 0x6D13, 0x61C0, 0x252E, 0x6CD4, 0x61E4}},
    // mode 5 UF16: endpoints (after transform) [[870, 876, 444], [862, 877, 432], [864, 870, 444], [866, 871, 445]]; unquantized [[27856, 28048, 14224], [27600, 28080, 13840], [27664, 27856, 14224], [27728, 27888, 14256]]
    {5, false, {{"rw", 870}, {"rx", 8}, {"ry", 10}, {"rz", 12}, {"gw", 876}, {"gx", 1}, {"gy", 10}, {"gz", 11}, {"bw", 444}, {"bx", 20}, {"by", 0}, {"bz", 1}}, 3, {1, 4, 3, 7, 7, 6, 3, 4, 4, 4, 1, 1, 1, 6, 4, 2},
     {0x34A3, 0x3514, 0x1ACF, 0x346D, 0x351A, 0x1A7E, 0x3480, 0x3518, 0x1A9B, 0x3476, 0x34C4, 0x1AF9, 0x3438, 0x3521, 0x1A2F, 0x344A, 0x351F, 0x1A49, 0x3464, 0x34BB, 0x1AF0, 0x3469, 0x34BD, 0x1AF2, 0x346D, 0x351A, 0x1A7E, 0x346D, 0x351A, 0x1A7E, 0x345C, 0x34B7, 0x1AEC, 0x345C, 0x34B7, 0x1AEC, 0x34A3, 0x3514, 0x1ACF, 0x3472, 0x34C2, 0x1AF7, 0x3469, 0x34BD, 0x1AF2, 0x3460, 0x34B9, 0x1AEE}},
    // mode 6 UF16: endpoints (after transform) [[96, 481, 211], [107, 477, 211], [101, 468, 226], [106, 470, 211]]; unquantized [[12352, 61632, 27072], [13760, 61120, 27072], [12992, 59968, 28992], [13632, 60224, 27072]]
    {6, false, {{"rw", 96}, {"rx", 11}, {"ry", 5}, {"rz", 10}, {"gw", 481}, {"gx", 28}, {"gy", 19}, {"gz", 21}, {"bw", 211}, {"bx", 0}, {"by", 15}, {"bz", 0}}, 10, {3, 0, 0, 3, 4, 3, 7, 5, 2, 2, 4, 6, 2, 4, 5, 3},
     {0x187E, 0x7434, 0x3339, 0x175F, 0x749D, 0x3339, 0x175F, 0x749D, 0x3339, 0x187E, 0x7434, 0x3339, 0x18E9, 0x740D, 0x3339, 0x187E, 0x7434, 0x3339, 0x1A09, 0x73A5, 0x3339, 0x1973, 0x71D0, 0x343E, 0x181E, 0x7457, 0x3339, 0x18EC, 0x7199, 0x35D5, 0x1948, 0x71BE, 0x34C1, 0x199F, 0x71E1, 0x33BB, 0x18EC, 0x7199, 0x35D5, 0x1948, 0x71BE, 0x34C1, 0x1973, 0x71D0, 0x343E, 0x1917, 0x71AB, 0x3552}},
    // mode 7 UF16: endpoints (after transform) [[124, 15, 188], [126, 2, 188], [105, 1, 200], [148, 7, 187]]; unquantized [[31872, 3968, 48256], [32384, 640, 48256], [27008, 384, 51328], [38016, 1920, 48000]]
    {7, false, {{"rw", 124}, {"rx", 2}, {"ry", 45}, {"rz", 24}, {"gw", 15}, {"gx", 19}, {"gy", 18}, {"gz", 24}, {"bw", 188}, {"bx", 0}, {"by", 12}, {"bz", 31}}, 17, {2, 0, 0, 6, 1, 4, 1, 4, 2, 3, 4, 2, 5, 6, 4, 0},
     {0x3C93, 0x05BC, 0x5B4E, 0x331A, 0x00BA, 0x611E, 0x331A, 0x00BA, 0x611E, 0x4500, 0x0339, 0x5BB4, 0x3C70, 0x069F, 0x5B4E, 0x3CDD, 0x03DE, 0x5B4E, 0x3C70, 0x069F, 0x5B4E, 0x3F24, 0x0268, 0x5D7A, 0x3C93, 0x05BC, 0x5B4E, 0x3CB6, 0x04D9, 0x5B4E, 0x3CDD, 0x03DE, 0x5B4E, 0x3C93, 0x05BC, 0x5B4E, 0x3D00, 0x02FB, 0x5B4E, 0x3D23, 0x0218, 0x5B4E, 0x3CDD, 0x03DE, 0x5B4E, 0x3C4E, 0x0782, 0x5B4E}},
    // mode 8 UF16: endpoints (after transform) [[97, 31, 30], [101, 45, 25], [91, 13, 28], [94, 8, 35]]; unquantized [[24960, 8064, 7808], [25984, 11648, 6528], [23424, 3456, 7296], [24192, 2176, 9088]]
    {8, false, {{"rw", 97}, {"rx", 4}, {"ry", 26}, {"rz", 29}, {"gw", 31}, {"gx", 14}, {"gy", 46}, {"gz", 41}, {"bw", 30}, {"bx", 27}, {"by", 30}, {"bz", 5}}, 24, {2, 4, 1, 1, 0, 0, 1, 4, 4, 0, 2, 6, 1, 3, 1, 0},
     {0x2FC5, 0x112A, 0x0E17, 0x3058, 0x132D, 0x0D5F, 0x2C86, 0x0632, 0x0E48, 0x2C86, 0x0632, 0x0E48, 0x2F3A, 0x0F42, 0x0EC6, 0x2F3A, 0x0F42, 0x0EC6, 0x2F7F, 0x1036, 0x0E6E, 0x2D29, 0x0523, 0x0FC3, 0x3058, 0x132D, 0x0D5F, 0x2F3A, 0x0F42, 0x0EC6, 0x2FC5, 0x112A, 0x0E17, 0x2D91, 0x0475, 0x10B7, 0x2F7F, 0x1036, 0x0E6E, 0x300B, 0x121E, 0x0DC0, 0x2F7F, 0x1036, 0x0E6E, 0x2F3A, 0x0F42, 0x0EC6}},
    // mode 9 UF16: endpoints (after transform) [[56, 184, 33], [49, 172, 26], [45, 199, 47], [58, 171, 60]]; unquantized [[14464, 47232, 8576], [12672, 44160, 6784], [11648, 51072, 12160], [14976, 43904, 15488]]
    {9, false, {{"rw", 56}, {"rx", 25}, {"ry", 21}, {"rz", 2}, {"gw", 184}, {"gx", 20}, {"gy", 15}, {"gz", 19}, {"bw", 33}, {"bx", 57}, {"by", 14}, {"bz", 27}}, 31, {1, 3, 3, 3, 1, 7, 5, 3, 7, 0, 5, 2, 7, 3, 3, 0},
     {0x1AE3, 0x588C, 0x0FBF, 0x19EF, 0x56EA, 0x0ECB, 0x18B2, 0x5AE9, 0x19AA, 0x18B2, 0x5AE9, 0x19AA, 0x16EC, 0x5EB9, 0x17E4, 0x17FA, 0x538E, 0x0CD6, 0x18EE, 0x5530, 0x0DCA, 0x18B2, 0x5AE9, 0x19AA, 0x1C56, 0x5312, 0x1D4E, 0x1B5E, 0x595E, 0x103A, 0x18EE, 0x5530, 0x0DCA, 0x17CF, 0x5CD1, 0x18C7, 0x1C56, 0x5312, 0x1D4E, 0x18B2, 0x5AE9, 0x19AA, 0x19EF, 0x56EA, 0x0ECB, 0x1B5E, 0x595E, 0x103A}},
    // mode 10 UF16: endpoints (after transform) [[40, 2, 47], [11, 45, 3], [38, 62, 4], [14, 59, 8]]; unquantized [[41472, 2560, 48640], [11776, 46592, 3584], [39424, 64000, 4608], [14848, 60928, 8704]]
    {10, false, {{"rw", 40}, {"rx", 11}, {"ry", 38}, {"rz", 14}, {"gw", 2}, {"gx", 45}, {"gy", 62}, {"gz", 59}, {"bw", 47}, {"bx", 3}, {"by", 4}, {"bz", 8}}, 6, {0, 5, 7, 5, 3, 2, 0, 1, 4, 3, 6, 4, 6, 7, 2, 3},
     {0x4E78, 0x04D8, 0x5C08, 0x2615, 0x40B9, 0x1EC2, 0x1648, 0x5828, 0x06C8, 0x292C, 0x74EA, 0x0E4A, 0x36C3, 0x27FD, 0x3811, 0x3EAA, 0x1C46, 0x440E, 0x4A98, 0x7918, 0x08B8, 0x440E, 0x7846, 0x09CF, 0x2DFC, 0x3502, 0x2ABF, 0x36FA, 0x76A4, 0x0BFD, 0x22A2, 0x7419, 0x0F61, 0x2FB6, 0x75BB, 0x0D33, 0x22A2, 0x7419, 0x0F61, 0x1C18, 0x7348, 0x1078, 0x3D84, 0x7775, 0x0AE6, 0x36FA, 0x76A4, 0x0BFD}},
    // mode 11 UF16: endpoints (after transform) [[218, 211, 167], [223, 842, 130]]; unquantized [[13984, 13536, 10720], [14304, 53920, 8352]]
    {11, false, {{"rw", 218}, {"rx", 223}, {"gw", 211}, {"gx", 842}, {"bw", 167}, {"bx", 130}}, 0, {2, 12, 13, 1, 7, 5, 5, 3, 8, 14, 7, 1, 0, 15, 10, 2},
     {0x1A8B, 0x245B, 0x13A7, 0x1AF1, 0x5680, 0x10B6, 0x1AFA, 0x5B46, 0x106E, 0x1A7F, 0x1E63, 0x1400, 0x1ABE, 0x3D6D, 0x122E, 0x1AA8, 0x32AE, 0x12D0, 0x1AA8, 0x32AE, 0x12D0, 0x1A94, 0x2921, 0x135F, 0x1AC7, 0x4234, 0x11E7, 0x1B06, 0x613E, 0x1015, 0x1ABE, 0x3D6D, 0x122E, 0x1A7F, 0x1E63, 0x1400, 0x1A75, 0x199C, 0x1448, 0x1B10, 0x6605, 0x0FCD, 0x1ADD, 0x4CF3, 0x1145, 0x1A8B, 0x245B, 0x13A7}},
    // mode 12 UF16: endpoints (after transform) [[1381, 999, 207], [1428, 1078, 21]]; unquantized [[44208, 31984, 6640], [45712, 34512, 688]]
    {12, false, {{"rw", 1381}, {"rx", 47}, {"gw", 999}, {"gx", 79}, {"bw", 207}, {"bx", 326}}, 0, {5, 15, 7, 13, 12, 11, 4, 11, 5, 10, 15, 9, 8, 5, 15, 15},
     {0x5494, 0x3E16, 0x08DE, 0x567D, 0x414C, 0x014D, 0x54FA, 0x3EC2, 0x0748, 0x5617, 0x40A0, 0x02E2, 0x55EA, 0x4054, 0x0396, 0x55BC, 0x4007, 0x044B, 0x5467, 0x3DC9, 0x0992, 0x55BC, 0x4007, 0x044B, 0x5494, 0x3E16, 0x08DE, 0x558E, 0x3FBB, 0x04FF, 0x567D, 0x414C, 0x014D, 0x5555, 0x3F5B, 0x05E0, 0x5528, 0x3F0E, 0x0694, 0x5494, 0x3E16, 0x08DE, 0x567D, 0x414C, 0x014D, 0x567D, 0x414C, 0x014D}},
    // mode 13 UF16: endpoints (after transform) [[1020, 973, 874], [1023, 865, 871]]; unquantized [[16328, 15576, 13992], [16376, 13848, 13944]]
    {13, false, {{"rw", 1020}, {"rx", 3}, {"gw", 973}, {"gx", 148}, {"bw", 874}, {"bx", 253}}, 0, {1, 0, 9, 10, 1, 12, 1, 3, 8, 0, 11, 15, 12, 3, 15, 7},
     {0x1EE6, 0x1D44, 0x1A77, 0x1EE4, 0x1D78, 0x1A79, 0x1EF2, 0x1B87, 0x1A6B, 0x1EF4, 0x1B46, 0x1A69, 0x1EE6, 0x1D44, 0x1A77, 0x1EF7, 0x1ADD, 0x1A66, 0x1EE6, 0x1D44, 0x1A77, 0x1EE9, 0x1CCE, 0x1A74, 0x1EF1, 0x1BBB, 0x1A6D, 0x1EE4, 0x1D78, 0x1A79, 0x1EF5, 0x1B11, 0x1A68, 0x1EFC, 0x1A33, 0x1A62, 0x1EF7, 0x1ADD, 0x1A66, 0x1EE9, 0x1CCE, 0x1A74, 0x1EFC, 0x1A33, 0x1A62, 0x1EF0, 0x1BF0, 0x1A6E}},
    // mode 14 UF16: endpoints (after transform) [[56917, 6596, 23676], [56914, 6598, 23683]]; unquantized [[56917, 6596, 23676], [56914, 6598, 23683]]
    {14, false, {{"rw", 56917}, {"rx", 13}, {"gw", 6596}, {"gx", 2}, {"bw", 23676}, {"bx", 7}}, 0, {3, 8, 8, 9, 3, 3, 2, 10, 12, 8, 1, 2, 8, 2, 14, 10},
     {0x6BB0, 0x0C7A, 0x2CCC, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB0, 0x0C7A, 0x2CCC, 0x6BB0, 0x0C7A, 0x2CCC, 0x6BB1, 0x0C7A, 0x2CCC, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB1, 0x0C7A, 0x2CCC, 0x6BB1, 0x0C7A, 0x2CCC, 0x6BB0, 0x0C7B, 0x2CCE, 0x6BB1, 0x0C7A, 0x2CCC, 0x6BAF, 0x0C7B, 0x2CCF, 0x6BB0, 0x0C7B, 0x2CCE}},
    // mode 1 SF16: endpoints (after transform) [[444, 290, 210], [434, 289, 196], [444, 274, 216], [438, 299, 225]]; unquantized [[28448, 18592, 13472], [27808, 18528, 12576], [28448, 17568, 13856], [28064, 19168, 14432]]
    {1, true, {{"rw", 444}, {"rx", 22}, {"ry", 0}, {"rz", 26}, {"gw", 290}, {"gx", 31}, {"gy", 16}, {"gz", 9}, {"bw", 210}, {"bx", 18}, {"by", 6}, {"bz", 15}}, 10, {3, 2, 1, 5, 5, 4, 1, 2, 2, 2, 7, 7, 7, 4, 2, 0},
     {0x6AA1, 0x4640, 0x318C, 0x6AF8, 0x4649, 0x3206, 0x6B4F, 0x4652, 0x3280, 0x69E9, 0x462E, 0x308B, 0x69E9, 0x462E, 0x308B, 0x6A40, 0x4637, 0x3105, 0x6B4F, 0x4652, 0x3280, 0x6B3E, 0x442E, 0x350B, 0x6AF8, 0x4649, 0x3206, 0x6B3E, 0x442E, 0x350B, 0x6A33, 0x4889, 0x369D, 0x6A33, 0x4889, 0x369D, 0x6A33, 0x4889, 0x369D, 0x6ACF, 0x45FB, 0x35B1, 0x6B3E, 0x442E, 0x350B, 0x6BA7, 0x427B, 0x346F}},
    // mode 2 SF16: endpoints (after transform) [[-42, 55, 9], [-33, 49, 7], [-63, 48, 30], [-18, 58, -9]]; unquantized [[-21760, 28416, 4864], [-17152, 25344, 3840], [-32767, 24832, 15616], [-9472, 29952, -4864]]
    {2, true, {{"rw", 86}, {"rx", 9}, {"ry", 43}, {"rz", 24}, {"gw", 55}, {"gx", 58}, {"gy", 57}, {"gz", 3}, {"bw", 9}, {"bx", 62}, {"by", 21}, {"bz", 46}}, 17, {1, 6, 2, 1, 2, 1, 5, 3, 0, 0, 2, 4, 0, 2, 3, 5},
     {0xCFE4, 0x69E5, 0x11DC, 0xB03D, 0x6E9E, 0x8782, 0xE333, 0x636B, 0x254C, 0xEF99, 0x60B1, 0x3032, 0xCD70, 0x6843, 0x1151, 0xCFE4, 0x69E5, 0x11DC, 0xC5CF, 0x632D, 0x0F9F, 0xD6CE, 0x6624, 0x1A66, 0xD258, 0x6B88, 0x1268, 0xD258, 0x6B88, 0x1268, 0xCD70, 0x6843, 0x1151, 0xC843, 0x64CF, 0x102A, 0xD258, 0x6B88, 0x1268, 0xCD70, 0x6843, 0x1151, 0xCAFC, 0x66A0, 0x10C5, 0xC5CF, 0x632D, 0x0F9F}},
    // mode 3 SF16: endpoints (after transform) [[786, 517, 274], [786, 518, 272], [773, 509, 276], [792, 523, 271]]; unquantized [[25168, 16560, 8784], [25168, 16592, 8720], [24752, 16304, 8848], [25360, 16752, 8688]]
    {3, true, {{"rw", 786}, {"rx", 0}, {"ry", 19}, {"rz", 6}, {"gw", 517}, {"gx", 1}, {"gy", 8}, {"gz", 6}, {"bw", 274}, {"bx", 14}, {"by", 2}, {"bz", 13}}, 24, {0, 6, 2, 4, 7, 2, 7, 2, 0, 1, 2, 0, 3, 4, 2, 6},
     {0x5F3D, 0x3EAA, 0x213D, 0x5F3D, 0x3EC5, 0x2108, 0x5E50, 0x3E2C, 0x214F, 0x5EFF, 0x3EAD, 0x2122, 0x5F3D, 0x3EC9, 0x20FF, 0x5F3D, 0x3EB3, 0x212C, 0x5F3D, 0x3EC9, 0x20FF, 0x5E50, 0x3E2C, 0x214F, 0x5F3D, 0x3EAA, 0x213D, 0x5F3D, 0x3EAF, 0x2134, 0x5F3D, 0x3EB3, 0x212C, 0x5DAA, 0x3DB2, 0x217B, 0x5F3D, 0x3EB8, 0x2123, 0x5F3D, 0x3EBC, 0x2119, 0x5F3D, 0x3EB3, 0x212C, 0x5F3D, 0x3EC5, 0x2108}},
    // mode 4 SF16: endpoints (after transform) [[-617, 949, 532], [-615, 961, 525], [-617, 937, 536], [-622, 940, 535]]; unquantized [[-19760, 30384, 17040], [-19696, 30768, 16816], [-19760, 30000, 17168], [-19920, 30096, 17136]]
    {4, true, {{"rw", 1431}, {"rx", 2}, {"ry", 0}, {"rz", 11}, {"gw", 949}, {"gx", 12}, {"gy", 20}, {"gz", 23}, {"bw", 532}, {"bx", 9}, {"by", 4}, {"bz", 3}}, 31, {0, 2, 3, 7, 6, 6, 7, 2, 2, 6, 0, 4, 7, 1, 7, 6},
     {0xCAC6, 0x72FA, 0x407B, 0xCAB5, 0x7363, 0x403E, 0xCB07, 0x71AE, 0x40EA, 0xCB61, 0x71E3, 0x40D8, 0xCB4B, 0x71D6, 0x40DD, 0xCA91, 0x743A, 0x3FC1, 0xCA88, 0x746E, 0x3FA2, 0xCAF2, 0x71A0, 0x40EE, 0xCAF2, 0x71A0, 0x40EE, 0xCA91, 0x743A, 0x3FC1, 0xCAC6, 0x72FA, 0x407B, 0xCB1F, 0x71BC, 0x40E6, 0xCB61, 0x71E3, 0x40D8, 0xCADB, 0x7194, 0x40F3, 0xCA88, 0x746E, 0x3FA2, 0xCA91, 0x743A, 0x3FC1}},
    // mode 5 SF16: endpoints (after transform) [[-754, -18, -841], [-747, -16, -850], [-759, -13, -853], [-754, -17, -832]]; unquantized [[-24144, -592, -26928], [-23920, -528, -27216], [-24304, -432, -27312], [-24144, -560, -26640]]
    {5, true, {{"rw", 1294}, {"rx", 7}, {"ry", 11}, {"rz", 0}, {"gw", 2030}, {"gx", 2}, {"gy", 5}, {"gz", 1}, {"bw", 1207}, {"bx", 23}, {"by", 20}, {"bz", 9}}, 6, {3, 1, 1, 1, 7, 5, 3, 1, 5, 6, 3, 0, 5, 1, 1, 2},
     {0xDB01, 0x8223, 0xE65B, 0xDB3E, 0x8234, 0xE60D, 0xDB3E, 0x8234, 0xE60D, 0xDBE2, 0x81B3, 0xE6FE, 0xDA84, 0x81FF, 0xE6FD, 0xDAC1, 0x8210, 0xE6AF, 0xDBB6, 0x81D6, 0xE647, 0xDBE2, 0x81B3, 0xE6FE, 0xDAC1, 0x8210, 0xE6AF, 0xDB72, 0x820D, 0xE52A, 0xDBB6, 0x81D6, 0xE647, 0xDBF8, 0x81A2, 0xE75A, 0xDB89, 0x81FB, 0xE586, 0xDBE2, 0x81B3, 0xE6FE, 0xDBE2, 0x81B3, 0xE6FE, 0xDBCC, 0x81C5, 0xE6A3}},
    // mode 6 SF16: endpoints (after transform) [[30, -40, 165], [39, -29, 166], [42, -36, 175], [26, -31, 155]]; unquantized [[3904, -5184, 21184], [5056, -3776, 21312], [5440, -4672, 22464], [3392, -4032, 19904]]
    {6, true, {{"rw", 30}, {"rx", 9}, {"ry", 12}, {"rz", 28}, {"gw", 472}, {"gx", 11}, {"gy", 4}, {"gz", 9}, {"bw", 165}, {"bx", 1}, {"by", 10}, {"bz", 22}}, 13, {2, 3, 5, 3, 1, 0, 6, 7, 2, 1, 4, 2, 4, 5, 0, 1},
     {0x0FFF, 0x921E, 0x504C, 0x109C, 0x915E, 0x505E, 0x11E8, 0x8FC9, 0x5083, 0x109C, 0x915E, 0x505E, 0x0F62, 0x92DE, 0x503B, 0x0EC6, 0x939E, 0x502A, 0x1285, 0x8F09, 0x5094, 0x1322, 0x8E4A, 0x50A6, 0x1268, 0x90FF, 0x5248, 0x137F, 0x9156, 0x53A5, 0x101B, 0x9047, 0x4F68, 0x1268, 0x90FF, 0x5248, 0x101B, 0x9047, 0x4F68, 0x0F04, 0x8FF0, 0x4E0B, 0x1496, 0x91AE, 0x5502, 0x137F, 0x9156, 0x53A5}},
    // mode 7 SF16: endpoints (after transform) [[-16, 29, 3], [-19, 29, 2], [9, 37, 16], [8, 23, 6]]; unquantized [[-4224, 7552, 896], [-4992, 7552, 640], [2432, 9600, 4224], [2176, 6016, 1664]]
    {7, true, {{"rw", 240}, {"rx", 61}, {"ry", 25}, {"rz", 24}, {"gw", 29}, {"gx", 0}, {"gy", 8}, {"gz", 26}, {"bw", 3}, {"bx", 31}, {"by", 13}, {"bz", 3}}, 20, {3, 1, 2, 4, 5, 7, 6, 5, 0, 0, 3, 5, 5, 5, 5, 4},
     {0x9135, 0x1C94, 0x02FB, 0x9064, 0x1C94, 0x0341, 0x08EE, 0x2083, 0x0D42, 0x08A4, 0x1C7C, 0x0A62, 0x9212, 0x1C94, 0x02B1, 0x92E4, 0x1C94, 0x026C, 0x927B, 0x1C94, 0x028E, 0x0881, 0x1A94, 0x0905, 0x8FFC, 0x1C94, 0x0364, 0x8FFC, 0x1C94, 0x0364, 0x9135, 0x1C94, 0x02FB, 0x9212, 0x1C94, 0x02B1, 0x9212, 0x1C94, 0x02B1, 0x9212, 0x1C94, 0x02B1, 0x9212, 0x1C94, 0x02B1, 0x91AA, 0x1C94, 0x02D4}},
    // mode 8 SF16: endpoints (after transform) [[43, -30, 123], [40, -5, 115], [56, -52, -128], [54, -37, 114]]; unquantized [[11136, -7808, 31616], [10368, -1408, 29568], [14464, -13440, -32767], [13952, -9600, 29312]]
    {8, true, {{"rw", 43}, {"rx", 29}, {"ry", 13}, {"rz", 11}, {"gw", 226}, {"gx", 25}, {"gy", 42}, {"gz", 57}, {"bw", 123}, {"bx", 24}, {"by", 5}, {"bz", 23}}, 27, {2, 3, 1, 5, 2, 1, 3, 2, 0, 3, 7, 6, 7, 0, 7, 2},
     {0x2952, 0x96BC, 0x7576, 0x28EA, 0x9354, 0x745F, 0x3676, 0xB0D0, 0xDAF5, 0x3557, 0xA86A, 0x2CD9, 0x2952, 0x96BC, 0x7576, 0x3676, 0xB0D0, 0xDAF5, 0x35EA, 0xACBA, 0x98E3, 0x2952, 0x96BC, 0x7576, 0x2A24, 0x9D8C, 0x77A4, 0x35EA, 0xACBA, 0x98E3, 0x34CC, 0xA454, 0x6EEC, 0x27A4, 0x88BB, 0x70FB, 0x34CC, 0xA454, 0x6EEC, 0x36BC, 0xB2DC, 0xFBFF, 0x273C, 0x8554, 0x6FE4, 0x2952, 0x96BC, 0x7576}},
    // mode 9 SF16: endpoints (after transform) [[-9, -47, 53], [-24, -50, 74], [5, -61, 80], [-11, -62, 48]]; unquantized [[-2432, -12160, 13696], [-6272, -12928, 19072], [1408, -15744, 20608], [-2944, -16000, 12416]]
    {9, true, {{"rw", 247}, {"rx", 17}, {"ry", 14}, {"rz", 30}, {"gw", 209}, {"gx", 29}, {"gy", 18}, {"gz", 17}, {"bw", 53}, {"bx", 21}, {"by", 27}, {"bz", 59}}, 2, {2, 0, 2, 5, 1, 6, 6, 7, 1, 1, 0, 0, 2, 6, 7, 0},
     {0x8D4A, 0xAED5, 0x398C, 0x0554, 0xBB94, 0x4DFC, 0x00B2, 0xBBD9, 0x4544, 0x8682, 0xBC46, 0x37B4, 0x8B3F, 0xAE6C, 0x36B0, 0x88D3, 0xBC69, 0x3358, 0x88D3, 0xBC69, 0x3358, 0x8B24, 0xBC8C, 0x2EFC, 0x8B3F, 0xAE6C, 0x36B0, 0x0303, 0xBBB6, 0x49A0, 0x0554, 0xBB94, 0x4DFC, 0x0554, 0xBB94, 0x4DFC, 0x8D4A, 0xAED5, 0x398C, 0x88D3, 0xBC69, 0x3358, 0x8B24, 0xBC8C, 0x2EFC, 0x0554, 0xBB94, 0x4DFC}},
    // mode 10 SF16: endpoints (after transform) [[-2, 18, 24], [0, 20, -3], [4, -26, 22], [24, 8, -9]]; unquantized [[-2560, 18944, 25088], [0, 20992, -3584], [4608, -27136, 23040], [25088, 8704, -9728]]
    {10, true, {{"rw", 62}, {"rx", 0}, {"ry", 4}, {"rz", 24}, {"gw", 18}, {"gx", 20}, {"gy", 38}, {"gz", 8}, {"bw", 24}, {"bx", 61}, {"by", 22}, {"bz", 55}}, 9, {0, 0, 4, 5, 1, 0, 7, 3, 3, 2, 7, 0, 0, 0, 5, 1},
     {0x89B0, 0x47B0, 0x5EF0, 0x89B0, 0x47B0, 0x5EF0, 0x3E3E, 0x9847, 0x0F80, 0x4924, 0x8535, 0x81F0, 0x8853, 0x48C7, 0x4FAE, 0x1170, 0xE6B0, 0x5730, 0x5EF0, 0x20F0, 0xA4D0, 0x3222, 0xAD78, 0x22E0, 0x3222, 0xAD78, 0x22E0, 0x273C, 0xC08B, 0x3450, 0x5EF0, 0x20F0, 0xA4D0, 0x1170, 0xE6B0, 0x5730, 0x1170, 0xE6B0, 0x5730, 0x1170, 0xE6B0, 0x5730, 0x4924, 0x8535, 0x81F0, 0x1C56, 0xD39D, 0x45C0}},
    // mode 11 SF16: endpoints (after transform) [[-155, -424, 76], [274, 386, 199]]; unquantized [[-9952, -27168, 4896], [17568, 24736, 12768]]
    {11, true, {{"rw", 869}, {"rx", 274}, {"gw", 600}, {"gx", 386}, {"bw", 76}, {"bx", 199}}, 0, {1, 6, 13, 8, 15, 1, 15, 12, 11, 12, 11, 12, 12, 15, 8, 15},
     {0x9F26, 0xDA88, 0x1463, 0x04A5, 0x9703, 0x1EA1, 0x33D5, 0x41FC, 0x2C20, 0x11AA, 0x0189, 0x225A, 0x427B, 0x5D9B, 0x3051, 0x9F26, 0xDA88, 0x1463, 0x427B, 0x5D9B, 0x3051, 0x2D53, 0x35B5, 0x2A43, 0x26D1, 0x296E, 0x2867, 0x2D53, 0x35B5, 0x2A43, 0x26D1, 0x296E, 0x2867, 0x2D53, 0x35B5, 0x2A43, 0x2D53, 0x35B5, 0x2A43, 0x427B, 0x5D9B, 0x3051, 0x11AA, 0x0189, 0x225A, 0x427B, 0x5D9B, 0x3051}},
    // mode 12 SF16: endpoints (after transform) [[891, -146, 432], [-1012, -196, 346]]; unquantized [[28528, -4688, 13840], [-32400, -6288, 11088]]
    {12, true, {{"rw", 891}, {"rx", 145}, {"gw", 1902}, {"gx", 462}, {"bw", 432}, {"bx", 426}}, 0, {6, 0, 1, 3, 8, 14, 9, 4, 11, 15, 14, 4, 8, 12, 8, 11},
     {0x0E4A, 0x9433, 0x3024, 0x6BF4, 0x91BD, 0x345F, 0x5D8B, 0x921E, 0x33B8, 0x3D1F, 0x92F8, 0x3241, 0x8E88, 0x94F4, 0x2ED7, 0xEC32, 0x976A, 0x2A9C, 0x9CF1, 0x9555, 0x2E30, 0x2EB6, 0x9359, 0x319B, 0xBD5D, 0x962F, 0x2CB9, 0xFA9B, 0x97CB, 0x29F5, 0xEC32, 0x976A, 0x2A9C, 0x2EB6, 0x9359, 0x319B, 0x8E88, 0x94F4, 0x2ED7, 0xCBC6, 0x9690, 0x2C13, 0x8E88, 0x94F4, 0x2ED7, 0xBD5D, 0x962F, 0x2CB9}},
    // mode 13 SF16: endpoints (after transform) [[-1018, -1536, 621], [-1054, -1566, 693]]; unquantized [[-16296, -24584, 9944], [-16872, -25064, 11096]]
    {13, true, {{"rw", 3078}, {"rx", 220}, {"gw", 2560}, {"gx", 226}, {"bw", 621}, {"bx", 72}}, 0, {5, 0, 6, 7, 8, 14, 9, 2, 8, 4, 13, 0, 6, 9, 11, 10},
     {0xBE61, 0xDD9F, 0x270F, 0xBDAA, 0xDD07, 0x25A1, 0xBE8D, 0xDDC4, 0x2766, 0xBEB0, 0xDDE1, 0x27AC, 0xBED3, 0xDDFE, 0x27F2, 0xBFB5, 0xDEBB, 0x29B7, 0xBEF6, 0xDE1B, 0x2837, 0xBDF9, 0xDD48, 0x263E, 0xBED3, 0xDDFE, 0x27F2, 0xBE3E, 0xDD82, 0x26C9, 0xBF8A, 0xDE96, 0x2960, 0xBDAA, 0xDD07, 0x25A1, 0xBE8D, 0xDDC4, 0x2766, 0xBEF6, 0xDE1B, 0x2837, 0xBF44, 0xDE5C, 0x28D4, 0xBF21, 0xDE3F, 0x288F}},
    // mode 14 SF16: endpoints (after transform) [[11642, 22538, 2378], [11647, 22545, 2379]]; unquantized [[11642, 22538, 2378], [11647, 22545, 2379]]
    {14, true, {{"rw", 11642}, {"rx", 5}, {"gw", 22538}, {"gx", 7}, {"bw", 2378}, {"bx", 1}}, 0, {2, 0, 1, 5, 12, 12, 5, 8, 0, 4, 14, 2, 5, 15, 5, 12},
     {0x2C0F, 0x554A, 0x08FF, 0x2C0E, 0x5549, 0x08FF, 0x2C0E, 0x5549, 0x08FF, 0x2C10, 0x554B, 0x08FF, 0x2C12, 0x554F, 0x0900, 0x2C12, 0x554F, 0x0900, 0x2C10, 0x554B, 0x08FF, 0x2C11, 0x554D, 0x0900, 0x2C0E, 0x5549, 0x08FF, 0x2C0F, 0x554B, 0x08FF, 0x2C13, 0x5550, 0x0900, 0x2C0F, 0x554A, 0x08FF, 0x2C10, 0x554B, 0x08FF, 0x2C13, 0x5550, 0x0900, 0x2C10, 0x554B, 0x08FF, 0x2C12, 0x554F, 0x0900}},
};

TEST(Bc6hDecode, EveryModeBitByBit) {
    int modes_seen[2][15] = {};
    for (const Vector& v : kVectors) {
        const auto blk = build_block(v.mode, v.fields, v.partition, v.idx);
        EXPECT_EQ(bc6h_block_mode(blk.data()), v.mode);
        uint16_t h[48];
        decode_bc6h_block_half(blk.data(), v.is_signed, h);
        for (int i = 0; i < 48; ++i)
            ASSERT_EQ(h[i], v.halves[size_t(i)]) << "mode " << v.mode << (v.is_signed ? " SF16" : " UF16") << " texel " << i / 3 << " channel " << i % 3;
        ++modes_seen[v.is_signed][v.mode];
    }
    for (int s = 0; s < 2; ++s)
        for (int m = 1; m <= 14; ++m) EXPECT_EQ(modes_seen[s][m], 1) << m;
}

// Reserved headers 10011, 10111, 11011, 11111 decode to 0 whatever follows.
TEST(Bc6hDecode, ReservedModesDecodeToZero) {
    for (int header : {0x13, 0x17, 0x1B, 0x1F})
        for (bool sg : {false, true}) {
            uint8_t blk[16];
            for (int i = 0; i < 16; ++i) blk[i] = uint8_t(0xA5 ^ (i * 37));
            blk[0] = uint8_t((blk[0] & ~31) | header);
            EXPECT_EQ(bc6h_block_mode(blk), 0);
            float f[48];
            decode_bc6h_block(blk, sg, f);
            for (float x : f) EXPECT_EQ(x, 0.0f);
        }
}

// Any 128 bits decode to finite values within the half range (UF16 never negative).
TEST(Bc6hDecode, RandomBitsStayInRange) {
    for (uint64_t k = 0; k < 20000; ++k) {
        uint8_t blk[16];
        for (int i = 0; i < 16; ++i) blk[i] = uint8_t(test::unit(k, uint64_t(i)) * 256.0);
        for (bool sg : {false, true}) {
            float f[48];
            decode_bc6h_block(blk, sg, f);
            for (float x : f) {
                ASSERT_TRUE(std::isfinite(x) || sg) << k; // SF16 16-bit endpoint -32768 is the spec's one infinity
                if (std::isfinite(x)) {
                    ASSERT_LE(std::fabs(x), 65504.0f);
                }
                if (!sg) {
                    ASSERT_GE(x, 0.0f);
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------
// Encoder

// Block k of a mixed HDR stream: noise at magnitudes 2^-14..2^16, gradients, two-level,
// steps, constants, extremes (0 / 65504), denormals, narrow noise, mixed magnitudes.
// Signed blocks get negative values in most kinds.
int hdr_kind(uint64_t k) { return int(k % 9); }
void hdr_block(uint64_t k, bool sg, float out[48]) {
    using test::unit;
    const int kind = hdr_kind(k);
    const double scale = std::min(65504.0, std::exp2(-14.0 + 30.0 * unit(k, 1)));
    auto sgn = [&](uint64_t i) { return (sg && unit(k, 200 + i) < 0.5) ? -1.0 : 1.0; };
    double a[3], c[3];
    for (int ch = 0; ch < 3; ++ch) { a[ch] = unit(k, 2 + ch) * scale * sgn(uint64_t(ch)); c[ch] = unit(k, 5 + ch) * scale * sgn(uint64_t(3 + ch)); }
    for (int t = 0; t < 16; ++t) {
        const int x = t % 4, y = t / 4;
        for (int ch = 0; ch < 3; ++ch) {
            double v = 0;
            switch (kind) {
            case 0: v = unit(k, 10 + uint64_t(3 * t + ch)) * scale * sgn(uint64_t(10 + 3 * t + ch)); break;
            case 1: v = a[ch] + (c[ch] - a[ch]) * (x + y) / 6.0; break;
            case 2: v = unit(k, 100 + uint64_t(t)) < 0.5 ? a[ch] : c[ch]; break;
            case 3: v = x < 2 ? a[ch] : c[ch]; break;
            case 4: v = a[ch]; break;
            case 5: v = (t + ch) % 2 ? 65504.0 * sgn(uint64_t(t)) : 0.0; break;
            case 6: v = unit(k, 10 + uint64_t(3 * t + ch)) * std::exp2(-14.0) * sgn(uint64_t(t)); break;
            case 7: v = a[ch] * (1.0 + 0.01 * unit(k, 10 + uint64_t(3 * t + ch))); break;
            default: v = std::exp2(-10.0 + 25.0 * unit(k, 10 + uint64_t(3 * t + ch))) * sgn(uint64_t(3 * t + ch)); break;
            }
            out[3 * t + ch] = float(std::clamp(v, -65504.0, 65504.0));
        }
    }
}

// Independent measurement of an encoded block.
float measured_error(const uint8_t blk[16], bool sg, const float src[48], double* sum_sq = nullptr) {
    float dec[48];
    decode_bc6h_block(blk, sg, dec);
    float m = 0;
    double q = 0;
    for (int i = 0; i < 48; ++i) {
        const double d = double(dec[i]) - double(src[i]);
        m = std::max(m, float(std::fabs(d)));
        q += d * d;
    }
    if (sum_sq) *sum_sq = q;
    return m;
}

TEST(Bc6hEncode, RandomBlocksDecodeWithinReportedError) {
    for (bool sg : {false, true}) {
        BlockOptions o;
        o.quality = Quality::Normal;
        double worst_rel[9] = {};
        for (int k = 0; k < test::kRandomBlocks; ++k) {
            float src[48];
            hdr_block(uint64_t(k) + (sg ? 7777773u : 0u), sg, src); // the offset keeps the kind (multiple of 9)
            uint8_t blk[16];
            const BlockResult r = encode_bc6h_block(src, sg, o, blk);
            double q;
            const float m = measured_error(blk, sg, src, &q);
            ASSERT_EQ(m, r.max_error) << "block " << k;
            ASSERT_NEAR(q, r.sum_sq, 1e-9 * (1.0 + q));
            ASSERT_TRUE(std::isfinite(r.max_error));
            float amax = 0;
            for (float v : src) amax = std::max(amax, std::fabs(v));
            worst_rel[hdr_kind(uint64_t(k))] = std::max(worst_rel[hdr_kind(uint64_t(k))], amax > 0 ? double(m) / amax : double(m));
            if (!sg) {
                float dec[48];
                decode_bc6h_block(blk, sg, dec);
                for (float v : dec) ASSERT_GE(v, 0.0f);
            }
        }
        for (int kind = 0; kind < 9; ++kind) std::printf("%s kind %d: worst error / block max |value| = %.3g\n", sg ? "SF16" : "UF16", kind, worst_rel[kind]);
    }
}

// Nearest half-float value (round to nearest even), written from the IEEE definition.
double nearest_half(double v) {
    const double a = std::fabs(v);
    if (a >= 65520.0) return std::copysign(INFINITY, v);
    const double ulp = a < std::ldexp(1.0, -14) ? std::ldexp(1.0, -24) : std::ldexp(1.0, std::ilogb(a) - 10);
    return std::copysign(std::nearbyint(a / ulp) * ulp, v);
}

const Quality kQualities[3] = {Quality::Fast, Quality::Normal, Quality::Best};

TEST(Bc6hEncode, ConstantBlocksAreExactUpToHalfRounding) {
    for (bool sg : {false, true})
        for (float v : {0.0f, 1.0f, 3.14159f, 1000.3f, 60000.0f, 65504.0f, 1e-5f, 6e-8f, 2.98e-8f, 0.37f, 12345.678f}) {
            for (float sv : {v, -v}) {
                if (!sg && sv < 0) continue;
                float src[48];
                for (int i = 0; i < 48; ++i) src[i] = i % 3 == 1 ? sv * 0.5f : sv;
                const double expect = std::max(std::fabs(nearest_half(sv) - sv), std::fabs(nearest_half(sv * 0.5f) - double(sv * 0.5f)));
                for (Quality q : kQualities) {
                    BlockOptions o;
                    o.quality = q;
                    uint8_t blk[16];
                    const BlockResult r = encode_bc6h_block(src, sg, o, blk);
                    EXPECT_EQ(double(r.max_error), expect) << sv << (sg ? " SF16" : " UF16") << " quality " << quality_name(q);
                    EXPECT_EQ(measured_error(blk, sg, src), r.max_error);
                }
            }
        }
}

// Two-level blocks at the ends of the range are exact: 0, +-65504 are endpoint values.
// (0, +65504 and -65504 together are not: the midpoint of -65504..65504 is -2^-13.)
TEST(Bc6hEncode, ExtremesAtZeroAndHalfMaxAreExact) {
    const float pairs[3][2] = {{0.0f, 65504.0f}, {0.0f, -65504.0f}, {65504.0f, -65504.0f}};
    for (bool sg : {false, true})
        for (int p = 0; p < (sg ? 3 : 1); ++p)
            for (Quality q : kQualities) {
                float src[48];
                for (int t = 0; t < 16; ++t)
                    for (int c = 0; c < 3; ++c) src[3 * t + c] = pairs[p][(t * 7) % 3 == 0 ? 0 : 1]; // grey texels: two colours
                BlockOptions o;
                o.quality = q;
                uint8_t blk[16];
                const BlockResult r = encode_bc6h_block(src, sg, o, blk);
                EXPECT_EQ(r.max_error, 0.0f) << (sg ? "SF16 " : "UF16 ") << quality_name(q) << " pair " << p;
                EXPECT_EQ(measured_error(blk, sg, src), 0.0f);
            }
}

// Sanity bounds for structured blocks, relative to the block's largest magnitude m:
// two-level, steps and smooth gradients of one sign (values in [0.2 m, m]) stay within
// 10% of m plus the half-float denormal step (a sanity bound: the measured worst
// cases, printed, are 4.7% UF16 and 6.9% SF16). Interpolation is linear in the half bit
// patterns, not in value: across the 2.3 binades of [0.2 m, m] a 16-entry palette has
// value gaps of about 7.5% of m near the top, and the three channels bend differently.
TEST(Bc6hEncode, StructuredBlocksStayAccurate) {
    for (bool sg : {false, true}) {
        double worst = 0;
        for (uint64_t k = 0; k < 6000; ++k) {
            const double scale = std::min(65504.0, std::exp2(-12.0 + 28.0 * test::unit(k, 1)));
            const double sign = sg && (k & 1) ? -1.0 : 1.0;
            float src[48];
            double a[3], c[3], m = 0;
            for (int ch = 0; ch < 3; ++ch) {
                a[ch] = sign * scale * (0.2 + 0.8 * test::unit(k, 2 + uint64_t(ch)));
                c[ch] = sign * scale * (0.2 + 0.8 * test::unit(k, 5 + uint64_t(ch)));
                m = std::max({m, std::fabs(a[ch]), std::fabs(c[ch])});
            }
            const int kind = int(k % 3);
            for (int t = 0; t < 16; ++t)
                for (int ch = 0; ch < 3; ++ch) {
                    const int x = t % 4, y = t / 4;
                    const double v = kind == 0 ? (test::unit(k, 50 + uint64_t(t)) < 0.5 ? a[ch] : c[ch])
                                   : kind == 1 ? (x < 2 ? a[ch] : c[ch])
                                               : a[ch] + (c[ch] - a[ch]) * (x + y) / 6.0;
                    src[3 * t + ch] = float(v);
                }
            BlockOptions o;
            o.quality = Quality::Normal;
            uint8_t blk[16];
            const BlockResult r = encode_bc6h_block(src, sg, o, blk);
            ASSERT_LE(r.max_error, 0.10 * m + std::ldexp(1.0, -24)) << "block " << k << " kind " << kind << " scale " << scale;
            worst = std::max(worst, double(r.max_error) / m);
        }
        std::printf("%s structured: worst error / max |value| = %.4g\n", sg ? "SF16" : "UF16", worst);
    }
}

TEST(Bc6hEncode, QualityLevelsAreOrdered) {
    for (bool sg : {false, true})
        for (uint64_t k = 0; k < 900; ++k) {
            float src[48];
            hdr_block(k, sg, src);
            float e[3];
            for (int i = 0; i < 3; ++i) {
                BlockOptions o;
                o.quality = kQualities[i];
                uint8_t blk[16];
                e[i] = encode_bc6h_block(src, sg, o, blk).max_error;
            }
            // Scores are compared in float inside the encoder; allow float rounding.
            EXPECT_LE(e[1], e[0] * (1 + 1e-6f)) << k;
            EXPECT_LE(e[2], e[1] * (1 + 1e-6f)) << k;
        }
}

TEST(Bc6hEncode, OutOfRangeValuesAreClampedAndMeasured) {
    float src[48];
    for (int i = 0; i < 48; ++i) src[i] = 1.0f;
    src[5] = 1.0e6f;  // above the half range
    src[7] = -3.0f;   // negative for UF16
    BlockOptions o;
    uint8_t blk[16];
    const BlockResult r = encode_bc6h_block(src, false, o, blk);
    float dec[48];
    decode_bc6h_block(blk, false, dec);
    EXPECT_LE(dec[5], 65504.0f);
    EXPECT_GE(dec[7], 0.0f);
    EXPECT_EQ(r.max_error, measured_error(blk, false, src));
    EXPECT_GE(r.max_error, 1.0e6f - 65504.0f);
}

TEST(Bc6hEncode, NanAndInfAreErrorsNamingTheTexel) {
    float src[48] = {};
    src[3 * 5 + 1] = NAN;
    BlockOptions o;
    uint8_t blk[16];
    try {
        encode_bc6h_block(src, false, o, blk);
        FAIL() << "no exception";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("texel 5 channel 1"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
    }
    src[3 * 5 + 1] = 0;
    src[20] = INFINITY;
    EXPECT_THROW(encode_bc6h_block(src, true, o, blk), Error);
}

// A miss of max_error at Normal triggers the Best search: the result is never worse
// than Best's.
TEST(Bc6hEncode, MaxErrorMissFallsBackToBest) {
    int escalated = 0;
    for (uint64_t k = 0; k < 300; ++k) {
        float src[48];
        hdr_block(k * 9 + 1, false, src); // gradients
        BlockOptions n, b;
        n.quality = Quality::Normal;
        b.quality = Quality::Best;
        uint8_t blk[16];
        const float en = encode_bc6h_block(src, false, n, blk).max_error;
        const float eb = encode_bc6h_block(src, false, b, blk).max_error;
        n.max_error = 0; // unreachable in general: forces the fallback
        const float ef = encode_bc6h_block(src, false, n, blk).max_error;
        EXPECT_LE(ef, eb * (1 + 1e-6f));
        if (eb < en) ++escalated;
    }
    std::printf("best improved on normal in %d of 300 gradient blocks\n", escalated);
}

// The written indices are optimal for the written endpoints: for every texel, rewriting its
// index bits (positions from the spec: indices follow the 82 or 65 header/endpoint bits,
// anchors one bit shorter, the shape in bits 77..81) to any other legal value and decoding
// never gives that texel a smaller max-channel error.
TEST(Bc6hEncode, IndicesAreOptimalForTheWrittenPalette) {
    auto get = [](const uint8_t* b, int pos) { return (b[pos / 8] >> (pos % 8)) & 1; };
    auto set = [](uint8_t* b, int pos, int v) { b[pos / 8] = uint8_t((b[pos / 8] & ~(1 << (pos % 8))) | (v << (pos % 8))); };
    for (bool sg : {false, true})
        for (uint64_t k = 0; k < 3000; ++k) {
            float src[48];
            hdr_block(k * 7 + 3, sg, src);
            BlockOptions o;
            uint8_t blk[16];
            encode_bc6h_block(src, sg, o, blk);
            const int mode = bc6h_block_mode(blk);
            ASSERT_GE(mode, 1);
            const bool two = mode <= 10;
            int shape = 0;
            for (int i = 0; i < 5; ++i) shape |= get(blk, 77 + i) << i;
            float dec[48];
            decode_bc6h_block(blk, sg, dec);
            int pos = two ? 82 : 65;
            for (int t = 0; t < 16; ++t) {
                const int bits = (two ? 3 : 4) - ((t == 0 || (two && t == kTestAnchor[shape])) ? 1 : 0);
                auto texel_err = [&](const float* d) {
                    float m = 0;
                    for (int c = 0; c < 3; ++c) m = std::max(m, std::fabs(d[3 * t + c] - src[3 * t + c]));
                    return m;
                };
                const float chosen = texel_err(dec);
                for (int v = 0; v < (1 << bits); ++v) {
                    uint8_t alt[16];
                    std::memcpy(alt, blk, 16);
                    for (int i = 0; i < bits; ++i) set(alt, pos + i, (v >> i) & 1);
                    float d2[48];
                    decode_bc6h_block(alt, sg, d2);
                    ASSERT_LE(chosen, texel_err(d2)) << "block " << k << " texel " << t << " index " << v;
                }
                pos += bits;
            }
            ASSERT_EQ(pos, 128);
        }
}

// ---------------------------------------------------------------------------------
// Textures: DDS round trips, OpenImageIO as an independent decoder, input checks

fs::path temp_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("atlas_bc6h_" + name + "_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

// OIIO 2.4's DDS reader decodes BC6H itself: feed it random 128-bit blocks (every mode,
// every partition, reserved headers) and our encoder's output, and compare every value.
void compare_with_oiio(const DdsTexture& tex, const std::string& name, int& mismatches, int& infinities) {
    const fs::path p = temp_dir("oiio") / (name + ".dds");
    const std::vector<uint8_t> bytes = encode_dds(tex);
    {
        std::ofstream f(p, std::ios::binary);
        f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    const Field3D ours = decode_texture(read_dds_file(p), nullptr);
    auto in = OIIO::ImageInput::open(p.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.width, tex.width);
    ASSERT_EQ(spec.height, tex.height);
    ASSERT_EQ(spec.nchannels, 3);
    std::vector<float> px(size_t(tex.width) * size_t(tex.height) * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data()));
    in->close();
    // OIIO's row `row` (from the top) is field row height - 1 - row (fields are y-up).
    for (int row = 0; row < tex.height; ++row)
        for (int x = 0; x < tex.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const int y = tex.height - 1 - row;
                const float theirs = px[(size_t(row) * size_t(tex.width) + size_t(x)) * 3 + size_t(c)];
                const float mine = ours.at(c, x, y, 0);
                if (std::isinf(mine)) ++infinities;
                if (!(theirs == mine) && !(std::isnan(theirs) && std::isnan(mine))) {
                    if (mismatches < 5)
                        std::printf("%s: texel (%d, %d) channel %d: OIIO %.9g, Atlas %.9g\n", name.c_str(), x, y, c, theirs, mine);
                    ++mismatches;
                }
            }
}

TEST(Bc6hTexture, OpenImageIoDecodesRandomBlocksIdentically) {
    for (bool sg : {false, true}) {
        DdsTexture tex;
        tex.format = sg ? DxgiFormat::BC6H_SF16 : DxgiFormat::BC6H_UF16;
        tex.width = 256;
        tex.height = 256;
        tex.data.resize(tex.total_bytes());
        for (size_t i = 0; i < tex.data.size(); ++i) tex.data[i] = uint8_t(test::unit(sg ? 99 : 98, i) * 256.0);
        int mismatches = 0, infinities = 0;
        compare_with_oiio(tex, sg ? "random_sf16" : "random_uf16", mismatches, infinities);
        std::printf("%s: %d of %d values differ from OIIO (%d infinities from the SF16 16-bit endpoint -32768)\n",
                    sg ? "SF16" : "UF16", mismatches, 256 * 256 * 3, infinities);
        EXPECT_EQ(mismatches, 0);
    }
}

Field3D hdr_volume(int nx, int ny, int nz, bool sg) {
    Field3D f(Vec3i{{nx, ny, nz}}, 3, Box3d{{{0, 0, 0}}, {{double(nx), double(ny), double(nz)}}});
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                const double d = std::sqrt(double((x - 12) * (x - 12) + (y - 20) * (y - 20) + 4 * (z - 3) * (z - 3)));
                f.at(0, x, y, z) = float(200.0 * std::exp(-d / 6.0));                       // radiance falling off
                f.at(1, x, y, z) = float(0.5 + 0.4 * std::sin(0.3 * x + 0.2 * y + 0.5 * z)); // density-like
                f.at(2, x, y, z) = float((sg ? -1.0 : 1.0) * 1e-3 * (1 + x + y));            // small values
            }
    return f;
}

TEST(Bc6hTexture, VolumeRoundTripThroughDdsWithMips) {
    for (Format fmt : {Format::Bc6hUf16, Format::Bc6hSf16}) {
        const Field3D src = hdr_volume(32, 32, 8, fmt == Format::Bc6hSf16);
        const fs::path p = temp_dir("volume") / (std::string(format_name(fmt)) + ".dds");
        CompressOptions o;
        o.format = fmt;
        o.mip_levels = 0;
        const CompressReport rep = compress_to_dds(src, p, o);
        const DdsTexture tex = read_dds_file(p);
        EXPECT_TRUE(tex.volume);
        EXPECT_EQ(tex.mip_levels, 6); // 32 -> 1
        EXPECT_EQ(tex.depth, 8);
        EXPECT_EQ(tex.format, fmt == Format::Bc6hSf16 ? DxgiFormat::BC6H_SF16 : DxgiFormat::BC6H_UF16);
        // Level 0 through the public reader, compared here independently.
        const Field3D back = read_dds(p);
        double worst = 0;
        for (int c = 0; c < 3; ++c)
            for (size_t i = 0; i < src.channel(c).size(); ++i)
                worst = std::max(worst, double(std::fabs(back.channel(c)[i] - src.channel(c)[i])));
        EXPECT_EQ(worst, rep.bound_max_error);
        EXPECT_LE(worst, 0.06 * 200.0); // sanity: a few percent of the largest value
        const CompressReport v = verify_dds(p, src);
        EXPECT_EQ(v.bound_max_error, rep.bound_max_error);
        // Mip 1 (16x16x4, 2x2x2 box) decoded block by block against the box-filtered source.
        const int w = 16, h = 16, d = 4;
        const uint8_t* base = tex.data.data() + tex.offset(0, 1);
        double mip_worst = 0;
        for (int z = 0; z < d; ++z)
            for (int by = 0; by < h / 4; ++by)
                for (int bx = 0; bx < w / 4; ++bx) {
                    float dec[48];
                    decode_bc6h_block(base + ((size_t(z) * 4 + size_t(by)) * 4 + size_t(bx)) * 16, fmt == Format::Bc6hSf16, dec);
                    for (int t = 0; t < 16; ++t)
                        for (int c = 0; c < 3; ++c) {
                            // DDS rows run top-down: mip row `row` is field row h - 1 - row.
                            const int x = bx * 4 + t % 4, row = by * 4 + t / 4, y = h - 1 - row;
                            double sum = 0;
                            for (int k = 0; k < 8; ++k) sum += src.at(c, 2 * x + (k & 1), 2 * y + (k >> 1 & 1), 2 * z + (k >> 2));
                            mip_worst = std::max(mip_worst, std::fabs(dec[3 * t + c] - sum / 8));
                        }
                }
        // Sanity, like level 0's: a few percent of the largest value. Measured 5.8% (uf16) and
        // 6.8% (sf16) since DDS rows became top-down (each block holds its rows in the other
        // order, so the partition search lands elsewhere; it was under 6% before).
        EXPECT_LE(mip_worst, 0.075 * 200.0);
        std::printf("%s volume: level 0 max error %.4g, mip 1 max error %.4g\n", format_name(fmt), worst, mip_worst);
        // The manifest states the format and the (absent) bound.
        std::ifstream mf(p.string() + ".json");
        std::stringstream ms;
        ms << mf.rdbuf();
        const TextureManifest man = TextureManifest::from_json(ms.str(), "manifest");
        EXPECT_EQ(man.encoding, format_name(fmt));
        EXPECT_EQ(man.dxgi_format, fmt == Format::Bc6hSf16 ? "BC6H_SF16" : "BC6H_UF16");
        EXPECT_FALSE(man.max_error.has_value());
        // Identity mapping: value_range is the data's own min and max (not a rescale).
        float lo = INFINITY, hi = -INFINITY;
        for (int c = 0; c < 3; ++c)
            for (float x : src.channel(c)) lo = std::min(lo, x), hi = std::max(hi, x);
        EXPECT_EQ(man.range_lo, lo);
        EXPECT_EQ(man.range_hi, hi);
        EXPECT_GT(hi, 1.0f); // the HDR test volume: a [0, 1] range would be wrong
    }
}

TEST(Bc6hTexture, EncoderOutputAgreesWithOpenImageIo) {
    CompressOptions o;
    o.format = Format::Bc6hSf16;
    const EncodedTexture e = encode_texture(hdr_volume(42, 30, 1, true), o); // not multiples of 4
    int mismatches = 0, infinities = 0;
    compare_with_oiio(e.dds, "encoded_sf16", mismatches, infinities);
    EXPECT_EQ(mismatches, 0);
    EXPECT_EQ(infinities, 0);
}

TEST(Bc6hTexture, BytesDoNotDependOnThreadCount) {
    CompressOptions o;
    o.format = Format::Bc6hUf16;
    o.mip_levels = 0;
    const Field3D src = hdr_volume(32, 24, 4, false);
    std::vector<uint8_t> one, many;
    {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
        one = encode_texture(src, o).dds.data;
    }
    many = encode_texture(src, o).dds.data;
    EXPECT_EQ(one, many);
}

TEST(Bc6hTexture, BoundMissesAreReportedWithPositionAndBestError) {
    CompressOptions o;
    o.format = Format::Bc6hUf16;
    o.max_error = 1e-4f; // below what the radiance falloff allows
    const Field3D src = hdr_volume(16, 16, 1, false);
    try {
        compress_to_dds(src, temp_dir("miss") / "m.dds", o);
        FAIL() << "no BoundError";
    } catch (const BoundError& e) {
        ASSERT_FALSE(e.report().blocks_over_bound.empty());
        for (const BlockMiss& m : e.report().blocks_over_bound) {
            EXPECT_GT(m.best_error, 1e-4f);
            EXPECT_EQ(m.x % 4, 0);
        }
        EXPECT_NE(std::string(e.what()).find("bc6h"), std::string::npos);
    }
    o.allow_over_bound = true;
    const CompressReport r = compress_to_dds(src, temp_dir("miss") / "m.dds", o);
    EXPECT_FALSE(r.blocks_over_bound.empty());
    float worst_miss = 0;
    for (const BlockMiss& m : r.blocks_over_bound) worst_miss = std::max(worst_miss, m.best_error);
    // The block search measures |decoded - source| in float, the verification in double:
    // equal up to float rounding (a few ulps), never smaller.
    EXPECT_NEAR(double(worst_miss), r.bound_max_error, r.bound_max_error * 1e-6);
    EXPECT_GE(double(worst_miss), r.bound_max_error) << "the search must not under-state a miss";
    // A reachable bound passes.
    o.max_error = float(r.bound_max_error) * 1.01f;
    o.allow_over_bound = false;
    EXPECT_NO_THROW(compress_to_dds(src, temp_dir("miss") / "m.dds", o));
}

TEST(Bc6hTexture, InvalidInputIsAClearError) {
    Field3D f = hdr_volume(8, 8, 1, false);
    CompressOptions o;
    o.format = Format::Bc6hUf16;
    auto expect_error = [&](const std::string& needle) {
        try {
            encode_texture(f, o);
            ADD_FAILURE() << "no error for " << needle;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    f.at(2, 3, 5, 0) = -1.0f;
    expect_error("texel (3, 5, 0)");
    expect_error("negative");
    o.format = Format::Bc6hSf16;
    EXPECT_NO_THROW(encode_texture(f, o));
    f.at(1, 2, 2, 0) = 70000.0f;
    expect_error("65504");
    f.at(1, 2, 2, 0) = NAN;
    expect_error("NaN");
    f.at(1, 2, 2, 0) = 0.0f;
    o.one_sided_below = true;
    expect_error("one-sided");
}

// A repeated flat block is answered from the thread's memo: the same bytes and result
// as a fresh encode on a new thread, for every signedness and option set in turn
// (leaving the signedness out of the memo's key fails here).
TEST(Bc6h, FlatBlockMemoEqualsAFreshEncode) {
    using test::unit;
    std::vector<std::array<float, 48>> blocks;
    auto flat = [&](float r, float g, float b) { blocks.push_back(test::flat_rgb_block(r, g, b)); };
    for (int k = 0; k < 30; ++k) {
        const float r = float(8 * unit(uint64_t(k), 1)), g = float(unit(uint64_t(k), 2)), b = float(0.01 * unit(uint64_t(k), 3));
        flat(r, g, b);
        flat(r, g, b);
        if (k % 3 == 0) { // a non-flat block between two flat ones of the same colour
            std::array<float, 48> a;
            for (int i = 0; i < 48; ++i) a[size_t(i)] = float(4 * unit(uint64_t(k), 10 + uint64_t(i)));
            blocks.push_back(a);
            flat(r, g, b);
        }
        if (k % 5 == 0) flat(r, g, std::nextafter(b, 2.0f)); // one ulp off: a different colour
    }
    std::vector<BlockOptions> opts(3);
    opts[0].quality = Quality::Fast;
    opts[2].max_error = 1e-4f;
    // Each block under each (options, signedness) twice in a row (the second from the
    // memo), in an order where consecutive encodes differ in one of the two only.
    const std::pair<int, bool> combos[] = {{0, false}, {0, true}, {1, true}, {1, false}, {2, false}, {2, true}};
    for (size_t i = 0; i < blocks.size(); ++i)
        for (const auto& [oi, sg] : combos)
            for (int rep = 0; rep < 2; ++rep) {
                const BlockOptions& o = opts[size_t(oi)];
                uint8_t a[16], b[16];
                const BlockResult ra = encode_bc6h_block(blocks[i].data(), sg, o, a);
                BlockResult rb;
                std::thread([&, sg = sg] { rb = encode_bc6h_block(blocks[i].data(), sg, o, b); }).join();
                ASSERT_EQ(std::memcmp(a, b, 16), 0) << "block " << i << " options " << oi << " signed " << sg << " repeat " << rep;
                ASSERT_EQ(std::memcmp(&ra.max_error, &rb.max_error, 4), 0) << "block " << i;
                ASSERT_EQ(std::memcmp(&ra.sum_sq, &rb.sum_sq, 8), 0) << "block " << i;
            }
}

} // namespace
} // namespace atlas::compress
