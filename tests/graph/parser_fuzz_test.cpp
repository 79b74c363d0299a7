// Robustness: thousands of deterministic mutations of valid graph files must
// each parse or fail with an atlas::Error - never crash, hang or throw
// anything else. (A libFuzzer target can reuse parse_graph the same way.)
#include "atlas/core/hash.h"
#include "atlas/graph/graph.h"
#include "../support/test_nodes.h"

#include <gtest/gtest.h>

using namespace atlas;

namespace {
const char* kSeedGraph = R"(atlas: 1
nodes:
  base:
    type: noise/value
    params: {resolution: [16, 16, 4], period: [2, 2, 1], octaves: 3, seed: 7}
  other:
    type: field/constant
    params: {resolution: [16, 16, 4], value: 0.25}
  mix:
    type: math/lerp
    inputs: {a: base, b: other.out}
    params: {t: 0.5}
  shaped:
    type: math/remap
    inputs:
      in: mix
    params:
      in_min: 0.2
      clamp: false
outputs:
  - {node: shaped, file: a.exr}
  - node: mix
    file: b.png
    options: {slice: 2}
)";

std::string mutate(std::string s, uint32_t seed) {
    static const char* tokens[] = {":", "-", "[", "]", "{", "}", ",", "\n", "  ", "'", "\"", "#", "&a", "*a", "!!int", "1e999",
                                   "nan", "-1", "99999999999999999999", "type", "inputs", "params", "atlas", "\t", "\x01", "..",
                                   "base", "mix.out", "noise/value", "[1, 2]", "{}", "null", "~", "true"};
    const int edits = 1 + int(hash_coords(seed, 0) % 4);
    for (int e = 0; e < edits && !s.empty(); ++e) {
        uint32_t h = hash_coords(seed, e + 1);
        size_t pos = hash_coords(seed, e + 1, 1) % s.size();
        switch (h % 4) {
        case 0: s.erase(pos, 1 + hash_coords(seed, e, 2) % 8); break;
        case 1: s.insert(pos, tokens[hash_coords(seed, e, 3) % (sizeof(tokens) / sizeof(tokens[0]))]); break;
        case 2: s[pos] = char(hash_coords(seed, e, 4) % 128); break;
        default: {
            size_t from = hash_coords(seed, e, 5) % s.size();
            s.insert(pos, s.substr(from, 1 + hash_coords(seed, e, 6) % 40));
        }
        }
    }
    return s;
}
} // namespace

TEST(GraphParseFuzz, MutatedGraphsFailCleanly) {
    auto reg = test::test_registry(std::make_shared<test::CookLog>());
    ASSERT_NO_THROW(parse_graph(kSeedGraph, "seed.yaml", ".", reg));
    int parsed = 0, rejected = 0;
    for (uint32_t seed = 0; seed < 3000; ++seed) {
        std::string text = mutate(kSeedGraph, seed);
        try {
            parse_graph(text, "m.yaml", ".", reg);
            ++parsed;
        } catch (const ParseError& e) {
            ++rejected;
            EXPECT_EQ(std::string(e.what()).rfind("m.yaml", 0), 0u) << "error does not name the file: " << e.what();
        } catch (const Error&) {
            ++rejected;
        } catch (const std::exception& e) {
            ADD_FAILURE() << "seed " << seed << ": non-Atlas exception " << e.what() << "\n" << text;
        }
    }
    EXPECT_GT(rejected, 1000);
    EXPECT_GT(parsed, 10);
}
