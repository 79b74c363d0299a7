// Evaluation order, laziness, caching (memory and disk), checked mode,
// determinism across thread counts, atomic outputs, budgets, cancellation.
#include "atlas/core/files.h"
#include "atlas/graph/disk_cache.h"
#include "atlas/graph/evaluator.h"
#include "../support/test_nodes.h"
#include "../../libatlas/src/graph/value_cache.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <limits>
#include <fstream>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace atlas;
namespace fs = std::filesystem;

namespace {

const char* kGraph = R"(atlas: 1
nodes:
  a:
    type: test/source
    params: {value: 2}
  b:
    type: test/source
    params: {value: 3}
  unused:
    type: test/source
  sum:
    type: test/add
    inputs: {a: a, b: b}
  gate:
    type: test/fail
    inputs: {in: sum}
outputs:
  - {node: sum, file: sum.exr}
  - {node: gate, file: sub/gate.exr}
)";

struct Fixture : ::testing::Test {
    std::shared_ptr<test::CookLog> log = std::make_shared<test::CookLog>();
    fs::path dir;
    void SetUp() override {
        dir = fs::temp_directory_path() / ("atlas_eval_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                                           ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }
    Session session(const std::string& text = kGraph) {
        Session s(test::test_registry(log));
        s.load_text(text, "test.yaml", dir);
        return s;
    }
    CookOptions options() {
        CookOptions o;
        o.out_dir = dir / "out";
        return o;
    }
    // For tests of the value caches: every output is written, so the nodes
    // behind it are needed (up-to-date outputs would need nothing).
    CookOptions writing_options() {
        CookOptions o = options();
        o.reuse_outputs = false;
        return o;
    }
};

std::string slurp(const fs::path& p) { return read_file_bytes(p); }

} // namespace

TEST_F(Fixture, CooksOnlyWhatOutputsNeed) {
    Session s = session();
    CookResult r = s.cook(options());
    EXPECT_EQ(log->count("unused"), 0);
    EXPECT_EQ(r.nodes.at("unused").status, "skipped");
    EXPECT_EQ(r.nodes.at("unused").reason, "not needed by the requested outputs");
    EXPECT_EQ(r.nodes.at("sum").status, "cooked");
    EXPECT_TRUE(fs::exists(dir / "out" / "sum.exr"));
    EXPECT_TRUE(fs::exists(dir / "out" / "sub" / "gate.exr"));
}

TEST_F(Fixture, RequestedOutputLimitsTheCook) {
    Session s = session();
    CookOptions o = options();
    o.outputs = {"sum.exr"};
    CookResult r = s.cook(o);
    EXPECT_EQ(log->count("gate"), 0);
    EXPECT_EQ(r.nodes.at("gate").status, "skipped");
    EXPECT_FALSE(fs::exists(dir / "out" / "sub" / "gate.exr"));
    o.outputs = {"summ.exr"};
    try {
        s.cook(o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("unknown output 'summ.exr' (did you mean 'sum.exr'?)"), std::string::npos) << e.what();
    }
}

TEST_F(Fixture, SecondCookCooksNothingAndParameterChangeRecooksDownstreamOnly) {
    Session s = session();
    s.cook(writing_options());
    CookResult second = s.cook(writing_options());
    EXPECT_TRUE(second.with_status("cooked").empty());
    EXPECT_EQ(second.nodes.at("sum").status, "cached");
    EXPECT_EQ(second.nodes.at("a").status, "skipped"); // not even loaded: sum came from cache
    s.set("b", "value", 5.0);
    CookResult third = s.cook(writing_options());
    EXPECT_EQ(third.with_status("cooked"), (std::vector<std::string>{"b", "gate", "sum"}));
    EXPECT_EQ(third.nodes.at("a").status, "cached");
    EXPECT_EQ(log->count("a"), 1);
    EXPECT_EQ(log->count("b"), 2);
}

TEST_F(Fixture, HashCoversParametersInputsAndTypeButNotUnusedNodes) {
    Session s = session();
    auto h1 = s.node_hashes();
    s.set("unused", "value", 9.0);
    auto h2 = s.node_hashes();
    EXPECT_EQ(h1.at("sum"), h2.at("sum"));
    EXPECT_NE(h1.at("unused"), h2.at("unused"));
    s.set("a", "value", 9.0);
    auto h3 = s.node_hashes();
    EXPECT_NE(h1.at("a"), h3.at("a"));
    EXPECT_NE(h1.at("sum"), h3.at("sum"));
    EXPECT_NE(h1.at("gate"), h3.at("gate"));
    EXPECT_EQ(h1.at("b"), h3.at("b"));
    // Same parameters on two nodes of one type: same content hash (shared cache entry).
    s.set("a", "value", 3.0);
    EXPECT_EQ(s.node_hashes().at("a"), s.node_hashes().at("b"));
}

TEST_F(Fixture, DiskCacheServesANewSession) {
    CookOptions o = writing_options();
    o.cache_dir = dir / "cache";
    {
        Session s = session();
        s.cook(o);
    }
    int before = log->count("sum");
    Session s2 = session();
    CookResult r = s2.cook(o);
    EXPECT_EQ(log->count("sum"), before);
    EXPECT_EQ(r.nodes.at("gate").status, "cached");
    EXPECT_EQ(r.nodes.at("gate").reason, "disk cache");
    EXPECT_TRUE(fs::exists(dir / "out" / "sum.exr"));
}

TEST_F(Fixture, CorruptDiskCacheEntryIsAMissNotAnError) {
    CookOptions o = writing_options();
    o.cache_dir = dir / "cache";
    {
        Session s = session();
        s.cook(o);
    }
    for (const auto& e : fs::directory_iterator(dir / "cache")) {
        std::ofstream f(e.path(), std::ios::binary | std::ios::trunc);
        f << "garbage";
    }
    Session s2 = session();
    CookResult r = s2.cook(o);
    EXPECT_EQ(r.nodes.at("gate").status, "cooked");
}

// Entries are streamed from disk with every length checked against the file's
// size: an entry cut anywhere (a crash mid-write by another tool, a full disk)
// is a miss, and the node cooks again with the same result.
TEST_F(Fixture, TruncatedDiskCacheEntryIsAMiss) {
    CookOptions o = writing_options();
    o.cache_dir = dir / "cache";
    {
        Session s = session();
        s.cook(o);
    }
    std::vector<std::pair<fs::path, std::string>> entries;
    for (const auto& e : fs::directory_iterator(dir / "cache")) entries.push_back({e.path(), read_file_bytes(e.path())});
    ASSERT_FALSE(entries.empty());
    for (double cut : {0.0, 0.001, 0.25, 0.5, 0.999}) {
        for (const auto& [path, bytes] : entries) {
            std::ofstream f(path, std::ios::binary | std::ios::trunc);
            f.write(bytes.data(), std::streamsize(double(bytes.size()) * cut));
        }
        Session s2 = session();
        CookResult r = s2.cook(o);
        EXPECT_EQ(r.nodes.at("gate").status, "cooked") << "cut at " << cut;
    }
}

TEST_F(Fixture, CheckedModeCatchesAnIncompleteHash) {
    const char* g = "atlas: 1\nnodes:\n  l:\n    type: test/leaky\noutputs:\n  - {node: l, file: l.exr}\n";
    Session s = session(g);
    CookOptions o = writing_options();
    s.cook(o);
    CookOptions checked = o;
    checked.checked = true;
    CookResult ok = s.cook(checked); // nothing changed: re-cook matches
    EXPECT_EQ(ok.nodes.at("l").status, "cooked");
    log->leaky_value = 2; // hidden input changed, hash did not
    EXPECT_EQ(s.cook(o).nodes.at("l").status, "cached"); // the bug: stale result served
    try {
        s.cook(checked);
        FAIL() << "checked mode should have caught the stale cache entry";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("checked mode: node 'l' (test/leaky): output 'out' differs from the cached result"),
                  std::string::npos) << e.what();
    }
}

TEST_F(Fixture, SameBytesWithOneAndTwoThreads) {
    const char* g = R"(atlas: 1
nodes:
  n:
    type: noise/value
    params: {resolution: [48, 40, 12], octaves: 4, seed: 3}
  m:
    type: noise/value
    params: {resolution: [48, 40, 12], octaves: 2, seed: 4}
  r:
    type: math/binary
    inputs: {a: n, b: m}
    params: {op: mul}
outputs:
  - {node: r, file: r.exr}
  - {node: r, file: r.vdb}
)";
    std::string bytes[2][2];
    for (int jobs = 1; jobs <= 2; ++jobs) {
        Session s = session(g);
        CookOptions o = options();
        o.jobs = jobs;
        o.out_dir = dir / ("j" + std::to_string(jobs));
        s.cook(o);
        bytes[jobs - 1][0] = slurp(o.out_dir / "r.exr");
        bytes[jobs - 1][1] = slurp(o.out_dir / "r.vdb");
    }
    EXPECT_EQ(bytes[0][0], bytes[1][0]);
    EXPECT_EQ(bytes[0][1], bytes[1][1]);
    EXPECT_GT(bytes[0][0].size(), 1000u);
}

// Two noise fields for the output tests below; each adds its outputs.
constexpr const char* kTwoNoises = R"(atlas: 1
nodes:
  n:
    type: noise/value
    params: {resolution: [32, 32, 8], octaves: 3, seed: 5}
  m:
    type: noise/value
    params: {resolution: [32, 32, 8], octaves: 2, seed: 6}
outputs:
)";

// Outputs are encoded together (up to the cook's jobs) and finished in graph order: the
// same bytes, the same report and the same failure as one at a time.
TEST_F(Fixture, OutputsWrittenTogetherMatchOneAtATime) {
    const std::string g = std::string(kTwoNoises) + R"(  - {node: n, file: a.exr}
  - {node: m, file: b.vdb}
  - {node: n, file: c.dds, options: {encoding: bc4, max_error: 0.00001}}
  - {node: m, file: d.png}
  - {node: n, file: e/slice, format: tga-slices}
  - {node: m, file: f.exr, options: {half: true}}
)";
    std::vector<std::vector<std::string>> reports;
    std::vector<std::map<std::string, std::string>> files;
    for (int jobs : {1, 2, 4}) {
        Session s = session(g);
        CookOptions o = options();
        o.jobs = jobs;
        o.keep_going = true;
        o.out_dir = dir / ("j" + std::to_string(jobs));
        const CookResult r = s.cook(o);
        std::vector<std::string> rep;
        for (const auto& out : r.outputs) rep.push_back(out.file + " " + out.status + " " + std::to_string(out.files.size()));
        reports.push_back(rep);
        std::map<std::string, std::string> bytes;
        for (const auto& e : fs::recursive_directory_iterator(o.out_dir))
            if (e.is_regular_file() && e.path().filename() != ".atlas-outputs.json")
                bytes[e.path().lexically_relative(o.out_dir).generic_string()] = slurp(e.path());
        files.push_back(bytes);
    }
    ASSERT_EQ(reports[0].size(), 6u);
    EXPECT_EQ(reports[0][2], "c.dds failed 0");
    EXPECT_EQ(reports[0][4], "e/slice written 8");
    EXPECT_GT(files[0].size(), 8u); // 8 slices and the other files
    EXPECT_EQ(files[0].count("c.dds"), 0u);
    for (size_t k = 1; k < reports.size(); ++k) {
        EXPECT_EQ(reports[k], reports[0]) << "jobs run " << k;
        EXPECT_EQ(files[k], files[0]) << "jobs run " << k;
    }
    // Without keep going the cook stops at c.dds (its report ends there) and writes nothing.
    Session s = session(g);
    CookOptions o = options();
    o.jobs = 2;
    o.out_dir = dir / "strict";
    EXPECT_THROW(s.cook(o), Error);
    const CookResult& r = s.last_result();
    ASSERT_EQ(r.outputs.size(), 3u);
    EXPECT_EQ(r.outputs[2].status, "failed");
    EXPECT_EQ(r.error_output, "c.dds");
    EXPECT_FALSE(fs::exists(o.out_dir / "a.exr"));
}

// A sequence's next frame (issue 43 item 6): an output whose key is the one the session's
// last cook wrote into another folder is copied from there, not encoded again; files that
// changed since are not copied.
TEST_F(Fixture, UnchangedOutputsAreCopiedFromTheLastCooksFolder) {
    const std::string g = std::string(kTwoNoises) + R"(  - {node: n, file: n.exr}
  - {node: n, file: n.dds, options: {encoding: bc4}}
  - {node: m, file: m.png}
)";
    Session s = session(g);
    auto cook_into = [&](const std::string& folder) {
        CookOptions o = options();
        o.out_dir = dir / folder;
        std::map<std::string, std::string> status;
        for (const auto& out : s.cook(o).outputs) status[out.file] = out.status;
        return status;
    };
    EXPECT_EQ(cook_into("f0")["n.exr"], "written");
    s.set("m", "seed", int64_t(7));
    auto st = cook_into("f1");
    EXPECT_EQ(st["n.exr"], "copied");
    EXPECT_EQ(st["n.dds"], "copied");
    EXPECT_EQ(st["m.png"], "written");
    for (const char* f : {"n.exr", "n.dds", "n.dds.json"}) EXPECT_EQ(slurp(dir / "f1" / f), slurp(dir / "f0" / f)) << f;
    EXPECT_NE(slurp(dir / "f1" / "m.png"), slurp(dir / "f0" / "m.png"));
    // f1's n.exr changed behind the session's back: the next folder gets it encoded again.
    { std::ofstream(dir / "f1" / "n.exr", std::ios::app) << "x"; }
    s.set("m", "seed", int64_t(8));
    st = cook_into("f2");
    EXPECT_EQ(st["n.exr"], "written");
    EXPECT_EQ(st["n.dds"], "copied");
    EXPECT_EQ(slurp(dir / "f2" / "n.exr"), slurp(dir / "f0" / "n.exr"));
    // With rewrite asked for, nothing is copied.
    s.set("m", "seed", int64_t(9));
    CookOptions o = options();
    o.out_dir = dir / "f3";
    o.reuse_outputs = false;
    for (const auto& out : s.cook(o).outputs) EXPECT_EQ(out.status, "written") << out.file;
}

TEST_F(Fixture, FailedCookWritesNothingAndKeepsOldFiles) {
    fs::create_directories(dir / "out");
    { std::ofstream f(dir / "out" / "sum.exr"); f << "previous good file"; }
    Session s = session();
    log->fail = true;
    EXPECT_THROW(s.cook(options()), Error);
    EXPECT_EQ(slurp(dir / "out" / "sum.exr"), "previous good file");
    EXPECT_FALSE(fs::exists(dir / "out" / "sub" / "gate.exr"));
    for (const auto& e : fs::recursive_directory_iterator(dir / "out"))
        EXPECT_EQ(e.path().filename().string().find(".atlas-staging"), std::string::npos) << e.path();
}

TEST_F(Fixture, FailedWriterWritesNothing) {
    // The second output cannot be written (a directory is in the way after staging):
    // simulate by asking a 2D-only format for a 3D value with a bad option value.
    const char* g = "atlas: 1\nnodes:\n  a:\n    type: test/source\noutputs:\n  - {node: a, file: a.exr}\n  - {node: a, file: a.png, options: {slice: 99}}\n";
    Session s = session(g);
    EXPECT_THROW(s.cook(options()), Error);
    EXPECT_FALSE(fs::exists(dir / "out" / "a.exr"));
}

TEST_F(Fixture, ErrorNamesTheNode) {
    Session s = session();
    log->fail = true;
    try {
        s.cook(options());
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("node 'gate' (test/fail): simulated failure"), std::string::npos) << e.what();
    }
}

TEST_F(Fixture, OutputPathsMayNotEscapeOut) {
    const char* g = "atlas: 1\nnodes:\n  a:\n    type: test/source\noutputs:\n  - {node: a, file: ../escape.exr}\n";
    Session s = session(g);
    try {
        s.cook(options());
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("leaves the output directory"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "escape.exr"));
    CookOptions o = options();
    o.allow_outside_out = true;
    s.cook(o);
    EXPECT_TRUE(fs::exists(dir / "escape.exr"));
}

TEST_F(Fixture, SymlinkOutOfOutIsRefused) {
    fs::create_directories(dir / "out");
    fs::create_directories(dir / "elsewhere");
    fs::create_directory_symlink(dir / "elsewhere", dir / "out" / "link");
    const char* g = "atlas: 1\nnodes:\n  a:\n    type: test/source\noutputs:\n  - {node: a, file: link/a.exr}\n";
    Session s = session(g);
    EXPECT_THROW(s.cook(options()), Error);
    EXPECT_FALSE(fs::exists(dir / "elsewhere" / "a.exr"));
}

TEST_F(Fixture, MemoryBudgetRefusalNamesNodeAndSize) {
    const char* g = "atlas: 1\nnodes:\n  huge:\n    type: test/big\noutputs:\n  - {node: huge, file: h.exr}\n";
    Session s = session(g);
    try {
        s.cook(options());
        FAIL();
    } catch (const MemoryBudgetError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("node 'huge'"), std::string::npos) << m;
        EXPECT_NE(m.find("4096x4096x4096"), std::string::npos) << m;
        EXPECT_NE(m.find("1.0 TiB"), std::string::npos) << m;
        EXPECT_NE(m.find("memory budget of 8.0 GiB"), std::string::npos) << m;
    }
}

TEST_F(Fixture, CancellationStopsAndWritesNothing) {
    Session s = session();
    CookOptions o = options();
    o.progress.is_cancelled = [] { return true; };
    EXPECT_THROW(s.cook(o), CancelledError);
    EXPECT_FALSE(fs::exists(dir / "out" / "sum.exr"));
}

TEST_F(Fixture, ProgressReachesTheEnd) {
    Session s = session();
    CookOptions o = options();
    std::mutex m;
    double last = 0;
    int events = 0;
    o.progress.on_progress = [&](const ProgressEvent& e) {
        std::lock_guard<std::mutex> l(m);
        EXPECT_GE(e.fraction, 0.0);
        EXPECT_LE(e.fraction, 1.0);
        last = e.fraction;
        ++events;
    };
    s.cook(o);
    EXPECT_GT(events, 3);
    EXPECT_DOUBLE_EQ(last, 1.0);
}

// One 0..1 run per cook (issue 17): a node that reports several phases of its
// own 0..1, nodes of one level running side by side and the outputs written
// after them never send the bar back or to 100% before the end.
TEST_F(Fixture, ProgressIsOneMonotoneRun) {
  for (int jobs : {1, 2}) {
    NodeRegistry r = test::test_registry(log);
    r.add({.name = "test/phases", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.doc("Reports three phases of 0..1, then a constant field.");
               d.output("out", PortType::Field3D, "field");
               d.param_float("value", 1.0).range(-100, 100).describe("value");
           },
           .cook = [](CookContext& ctx) {
               for (int phase = 0; phase < 3; ++phase)
                   for (int k = 0; k <= 4; ++k) ctx.progress(k / 4.0);
               auto f = ctx.make_field3d({{8, 8, 4}}, 1, Box3d{{{0, 0, 0}}, {{8, 8, 4}}});
               std::fill(f->channel(0).begin(), f->channel(0).end(), float(ctx.get_float("value")));
               ctx.set_output("out", Field3DPtr(f));
           }});
    Session s(std::move(r));
    s.load_text("atlas: 1\nnodes:\n  p:\n    type: test/phases\n  q:\n    type: test/phases\n    params: {value: 2}\n"
                "outputs:\n  - {node: p, file: p.exr}\n  - {node: q, file: q.exr}\n",
                "test.yaml", dir);
    {
        CookOptions o = writing_options();
        o.jobs = jobs;
        std::mutex m;
        std::vector<ProgressEvent> events;
        o.progress.on_progress = [&](const ProgressEvent& e) {
            std::lock_guard<std::mutex> l(m);
            events.push_back(e);
        };
        s.cook(o);
        ASSERT_GT(events.size(), 6u);
        for (size_t i = 1; i < events.size(); ++i) EXPECT_GE(events[i].fraction, events[i - 1].fraction) << "event " << i << " " << events[i].task;
        EXPECT_DOUBLE_EQ(events.back().fraction, 1.0);
        EXPECT_EQ(events.back().done, events.back().total);
        EXPECT_EQ(events.back().total, 4); // two nodes and two outputs
        // 100% only once everything is done.
        for (const auto& e : events)
            if (e.fraction >= 1.0) {
                EXPECT_EQ(e.done, e.total) << e.task;
            }
    }
  }
}

TEST_F(Fixture, ReportJsonHasTheDocumentedKeys) {
    Session s = session();
    CookResult r = s.cook(options());
    auto j = nlohmann::json::parse(r.to_json("test.yaml"));
    EXPECT_EQ(j["atlas_report_version"], 1);
    for (const char* n : {"a", "b", "sum", "gate", "unused"}) {
        ASSERT_TRUE(j["nodes"].contains(n)) << n;
        for (const char* k : {"type", "status", "seconds", "bytes", "metrics"}) EXPECT_TRUE(j["nodes"][n].contains(k)) << n << "." << k;
    }
    EXPECT_EQ(j["nodes"]["sum"]["status"], "cooked");
    EXPECT_EQ(j["nodes"]["sum"]["bytes"], 8 * 8 * 4 * 4);
    EXPECT_EQ(j["nodes"]["unused"]["status"], "skipped");
    EXPECT_EQ(j["summary"]["skipped"], 1);
    EXPECT_EQ(j["outputs"].size(), 2u);
    EXPECT_EQ(j["outputs"][0]["written"].size(), 1u);
    // The budget and what the ledger counted: at least the one value 'sum' held
    // while its output was written, at most the budget.
    EXPECT_EQ(j["memory"]["budget"], MemoryBudget::kDefaultLimit);
    EXPECT_GE(j["memory"]["peak_counted"].get<uint64_t>(), uint64_t(8 * 8 * 4 * 4));
    EXPECT_LE(j["memory"]["peak_counted"].get<uint64_t>(), MemoryBudget::kDefaultLimit);
}

// `atlas cook`'s one-shot cook (keep_values false) frees each value once the nodes
// reading it are done; an editor's session (the default) keeps them all for the next edit.
TEST_F(Fixture, AOneShotCookFreesValuesOnceRead) {
    const char* chain = R"(atlas: 1
nodes:
  a: {type: test/source, params: {value: 2}}
  s1: {type: test/add, inputs: {a: a, b: a}}
  s2: {type: test/add, inputs: {a: s1, b: s1}}
  s3: {type: test/add, inputs: {a: s2, b: s2}}
outputs:
  - {node: s3, file: s3.exr}
)";
    const uint64_t field = 8 * 8 * 4 * sizeof(float);
    auto peak = [&](bool keep, CookResult* second) {
        Session s = session(chain);
        CookOptions o = writing_options();
        o.keep_values = keep;
        o.jobs = 1;
        const CookResult r = s.cook(o);
        if (second) *second = s.cook(o);
        return nlohmann::json::parse(r.to_json("chain.yaml"))["memory"]["peak_counted"].get<uint64_t>();
    };
    CookResult kept, freed;
    const uint64_t keep_peak = peak(true, &kept), free_peak = peak(false, &freed);
    // Kept: all four values at the end, and the writer's copy of s3.
    EXPECT_GE(keep_peak, 5 * field);
    // Freed: at most a node's inputs, its result and the writer's copy.
    EXPECT_LE(free_peak, 3 * field);
    // The kept session's next cook takes s3 from memory; the one-shot's cooks it again.
    EXPECT_EQ(kept.nodes.at("s3").status, "cached");
    EXPECT_EQ(freed.with_status("cooked"), (std::vector<std::string>{"a", "s1", "s2", "s3"}));
    EXPECT_EQ(slurp(dir / "out" / "s3.exr").size() > 0, true);
}

TEST_F(Fixture, GetReturnsAValueWithoutWriting) {
    Session s = session();
    Value v = s.get("sum", "out");
    auto f = std::get<Field3DPtr>(v);
    EXPECT_FLOAT_EQ(f->at(0, 3, 3, 1), 5.0f);
    EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST_F(Fixture, PackNodeStacksChannelsInOrder) {
    const char* g = R"(atlas: 1
nodes:
  x: {type: noise/value, params: {resolution: [8, 8, 2], seed: 1}}
  y: {type: noise/value, params: {resolution: [8, 8, 2], seed: 2}}
  p: {type: field/pack, inputs: {r: x, g: y}, params: {names: "first,second"}}
  bad: {type: field/pack, inputs: {r: x, b: y}}
outputs:
  - {node: p, file: p.exr}
)";
    Session s = session(g);
    auto p = std::get<Field3DPtr>(s.get("p", "out"));
    auto x = std::get<Field3DPtr>(s.get("x", "out"));
    auto y = std::get<Field3DPtr>(s.get("y", "out"));
    ASSERT_EQ(p->channels(), 2);
    EXPECT_EQ(p->channel_names(), (std::vector<std::string>{"first", "second"}));
    EXPECT_TRUE(std::equal(x->channel(0).begin(), x->channel(0).end(), p->channel(0).begin()));
    EXPECT_TRUE(std::equal(y->channel(0).begin(), y->channel(0).end(), p->channel(1).begin()));
    try {
        s.get("bad", "out");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("input 'b' is connected but an earlier one is not"), std::string::npos) << e.what();
    }
}

TEST_F(Fixture, DdsOutputReportsItsErrorInTheCookReport) {
    const char* g = R"(atlas: 1
nodes:
  n: {type: noise/value, params: {resolution: [16, 16, 2], octaves: 3}}
outputs:
  - {node: n, file: n.dds, options: {encoding: bc4, max_error: 0.1}}
  - {node: n, file: n.exr}
)";
    Session s = session(g);
    CookResult r = s.cook(options());
    ASSERT_EQ(r.outputs.size(), 2u);
    const auto& m = r.outputs[0].metrics;
    ASSERT_TRUE(m.count("max_error_0") && m.count("bound_max_error") && m.count("encode_seconds"));
    EXPECT_GT(m.at("max_error_0"), 0.0);           // BC4 of noise is lossy
    EXPECT_LE(m.at("max_error_0"), m.at("bound_max_error"));
    EXPECT_LE(m.at("bound_max_error"), 0.1);       // the requested bound holds
    EXPECT_EQ(m.at("blocks_over_bound"), 0.0);
    EXPECT_TRUE(r.outputs[1].metrics.empty());     // lossless EXR measures nothing
    auto j = nlohmann::json::parse(r.to_json("t.yaml"));
    EXPECT_TRUE(j["outputs"][0]["metrics"].contains("bound_max_error"));
    EXPECT_TRUE(fs::exists(dir / "out" / "n.dds.json"));
}

// ------------------------------------------------- unattended cooks (issue 17)

namespace {
int64_t mtime_ns(const fs::path& p) {
    return int64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(fs::last_write_time(p).time_since_epoch()).count());
}
const OutputReport& output_named(const CookResult& r, const std::string& file) {
    for (const auto& o : r.outputs)
        if (o.file == file) return o;
    throw std::runtime_error("no output " + file);
}
const char* kTwoOutputs = "atlas: 1\nnodes:\n  a:\n    type: test/source\n    params: {value: 2}\n  b:\n    type: test/source\n"
                          "    params: {value: 3}\noutputs:\n  - {node: a, file: a.exr}\n  - {node: b, file: sub/b.png, options: {slice: 1}}\n";
} // namespace

// An output whose key and file are unchanged is not written again (the file's
// mtime and bytes stay) and nothing cooks or loads for it, in a new session
// (as a new process would) with or without a disk cache.
TEST_F(Fixture, UnchangedOutputsAreNotRewrittenAndNothingCooks) {
    CookOptions o = options();
    Session s1 = session(kTwoOutputs);
    CookResult r1 = s1.cook(o);
    EXPECT_EQ(output_named(r1, "a.exr").status, "written");
    ASSERT_EQ(output_named(r1, "a.exr").files.size(), 1u);
    const fs::path a = dir / "out" / "a.exr", b = dir / "out" / "sub" / "b.png";
    const int64_t ta = mtime_ns(a), tb = mtime_ns(b);
    const std::string bytes_a = slurp(a);
    EXPECT_EQ(output_named(r1, "a.exr").files[0].hash, file_content_hash(a).hex());
    EXPECT_EQ(output_named(r1, "a.exr").files[0].bytes, bytes_a.size());

    Session s2 = session(kTwoOutputs);
    CookResult r2 = s2.cook(o);
    EXPECT_EQ(log->count("a"), 1);
    EXPECT_EQ(log->count("b"), 1);
    EXPECT_EQ(r2.nodes.at("a").status, "skipped");
    EXPECT_EQ(r2.nodes.at("a").reason, "not needed: the outputs it feeds are up to date");
    EXPECT_EQ(output_named(r2, "a.exr").status, "up to date");
    EXPECT_TRUE(output_named(r2, "a.exr").written.empty());
    ASSERT_EQ(output_named(r2, "a.exr").files.size(), 1u);
    EXPECT_EQ(output_named(r2, "a.exr").files[0].hash, output_named(r1, "a.exr").files[0].hash);
    EXPECT_EQ(mtime_ns(a), ta);
    EXPECT_EQ(mtime_ns(b), tb);

    // One parameter edit: only that output is written again.
    s2.set_text("b", "value", "4");
    CookResult r3 = s2.cook(o);
    EXPECT_EQ(log->count("a"), 1);
    EXPECT_EQ(log->count("b"), 2);
    EXPECT_EQ(output_named(r3, "a.exr").status, "up to date");
    EXPECT_EQ(output_named(r3, "sub/b.png").status, "written");
    EXPECT_EQ(mtime_ns(a), ta);
    EXPECT_EQ(slurp(a), bytes_a);

    // Output options are part of the key.
    Session s4 = session(std::string(kTwoOutputs).replace(std::string(kTwoOutputs).find("{slice: 1}"), 10, "{slice: 2}"));
    s4.set_text("b", "value", "4");
    EXPECT_EQ(output_named(s4.cook(o), "sub/b.png").status, "written");
}

// .atlas-outputs.json records each file's mtime as Unix time, the value stat(2)
// gives (the independent reader), not the file clock's own count.
TEST_F(Fixture, OutputRecordsHoldUnixMtimes) {
    Session s = session(kTwoOutputs);
    s.cook(options());
    const auto j = nlohmann::json::parse(slurp(dir / "out" / ".atlas-outputs.json"));
    int files = 0;
    for (const auto& [name, r] : j.at("outputs").items())
        for (const auto& f : r.at("files")) {
            struct stat st {};
            ASSERT_EQ(::stat((dir / "out" / f.at("path").get<std::string>()).c_str(), &st), 0) << name;
            const int64_t unix_ns = int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
            EXPECT_EQ(f.at("mtime_ns").get<int64_t>(), unix_ns) << name;
            ++files;
        }
    EXPECT_EQ(files, 2);
}

// The file on disk decides: a deleted, resized or edited output is written
// again; a touched one with the same bytes is not (its mtime stays the touched one).
TEST_F(Fixture, OutputChangedOnDiskIsWrittenAgain) {
    CookOptions o = options();
    session(kTwoOutputs).cook(o);
    const fs::path a = dir / "out" / "a.exr";
    const std::string good = slurp(a);

    fs::remove(a);
    EXPECT_EQ(output_named(session(kTwoOutputs).cook(o), "a.exr").status, "written");
    EXPECT_EQ(slurp(a), good);

    { std::ofstream(a, std::ios::binary | std::ios::app) << "x"; }
    EXPECT_EQ(output_named(session(kTwoOutputs).cook(o), "a.exr").status, "written");
    EXPECT_EQ(slurp(a), good);

    std::string edited = good;
    edited[edited.size() / 2] ^= 0x40; // same size, different bytes, new mtime
    { std::ofstream(a, std::ios::binary | std::ios::trunc) << edited; }
    EXPECT_EQ(output_named(session(kTwoOutputs).cook(o), "a.exr").status, "written");
    EXPECT_EQ(slurp(a), good);

    const auto touched = fs::file_time_type::clock::now() - std::chrono::hours(5);
    fs::last_write_time(a, touched);
    EXPECT_EQ(output_named(session(kTwoOutputs).cook(o), "a.exr").status, "up to date");
    EXPECT_EQ(fs::last_write_time(a), touched);

    // --rewrite (reuse_outputs = false) writes everything.
    CookOptions all = o;
    all.reuse_outputs = false;
    EXPECT_EQ(output_named(session(kTwoOutputs).cook(all), "a.exr").status, "written");
}

// A bit flipped anywhere in a cache entry is detected: the entry is discarded
// with a warning and the node cooks again, giving the same output bytes.
TEST_F(Fixture, FlippedBitInCacheEntryIsDetectedAndRecooked) {
    CookOptions o = options();
    o.cache_dir = dir / "cache";
    o.reuse_outputs = false;
    session().cook(o);
    const std::string good = slurp(dir / "out" / "sum.exr");
    std::vector<fs::path> entries;
    for (const auto& e : fs::directory_iterator(dir / "cache"))
        if (e.path().extension() == ".atlascache") entries.push_back(e.path());
    ASSERT_EQ(entries.size(), 4u); // a, b, sum, gate
    for (double at : {0.5, 0.97}) {
        for (const auto& p : entries) {
            std::string bytes = slurp(p);
            bytes[size_t(double(bytes.size()) * at)] ^= 0x01;
            std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
        }
        const int before = log->count("sum");
        CookResult r = session().cook(o);
        EXPECT_EQ(log->count("sum"), before + 1) << at;
        EXPECT_EQ(r.nodes.at("gate").status, "cooked");
        ASSERT_FALSE(r.warnings.empty());
        EXPECT_NE(r.warnings[0].find("checksum mismatch"), std::string::npos) << r.warnings[0];
        EXPECT_EQ(slurp(dir / "out" / "sum.exr"), good);
        // The re-cooked entries replaced the damaged ones: the next cook is clean.
        CookResult again = session().cook(o);
        EXPECT_TRUE(again.warnings.empty());
        EXPECT_EQ(again.nodes.at("gate").status, "cached");
    }
}

// An unwritable cache (here: a plain file where the directory should be)
// degrades to cooking without it, with a warning.
TEST_F(Fixture, UnwritableCacheDegradesToCookingWithoutIt) {
    CookOptions o = options();
    { std::ofstream(dir / "cache") << "not a directory"; }
    o.cache_dir = dir / "cache";
    CookResult r;
    ASSERT_NO_THROW(r = session().cook(o));
    ASSERT_EQ(r.warnings.size(), 1u); // once, not per node
    EXPECT_NE(r.warnings[0].find("without writing the cache"), std::string::npos) << r.warnings[0];
    EXPECT_TRUE(fs::exists(dir / "out" / "sum.exr"));
}

TEST_F(Fixture, PruneRemovesLeastRecentlyUsedFirst) {
    const fs::path c = dir / "cache";
    fs::create_directories(c);
    const auto now = fs::file_time_type::clock::now();
    for (int i = 0; i < 5; ++i) {
        const fs::path p = c / ("entry" + std::to_string(i) + ".atlascache");
        std::ofstream(p) << std::string(1000, 'x');
        fs::last_write_time(p, now - std::chrono::hours(10 - i)); // entry0 is the oldest
    }
    std::ofstream(c / "notes.txt") << std::string(5000, 'y'); // not an entry: never touched
    const auto r = disk_cache::prune(c, 2500);
    EXPECT_EQ(r.bytes_before, 5000u);
    EXPECT_EQ(r.removed_files, 3u);
    EXPECT_EQ(r.bytes_after, 2000u);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(fs::exists(c / ("entry" + std::to_string(i) + ".atlascache")), i >= 3) << i;
    EXPECT_TRUE(fs::exists(c / "notes.txt"));
}

// A cache hit refreshes the entry, so a cook's working set survives a prune
// to its own size; cache_max_bytes prunes after the cook.
TEST_F(Fixture, CacheSizeLimitKeepsWhatTheCookUsed) {
    CookOptions o = options();
    o.cache_dir = dir / "cache";
    o.reuse_outputs = false;
    session().cook(o);
    uint64_t used = 0;
    for (const auto& e : fs::directory_iterator(dir / "cache")) used += e.file_size();
    // An old, unrelated entry.
    const fs::path stale = dir / "cache" / "00000000000000000000000000000000.atlascache";
    std::ofstream(stale) << std::string(4000, 'z');
    fs::last_write_time(stale, fs::file_time_type::clock::now() - std::chrono::hours(48));
    o.cache_max_bytes = used;
    CookResult r = session().cook(o);
    EXPECT_EQ(r.nodes.at("gate").status, "cached");
    EXPECT_FALSE(fs::exists(stale));
    uint64_t left = 0;
    for (const auto& e : fs::directory_iterator(dir / "cache")) left += e.file_size();
    EXPECT_EQ(left, used);
}

// Staging folders of a killed cook (its process is gone) are removed by the
// next cook, in --out and in the cache; a running process's are not.
TEST_F(Fixture, StagingLeftByAKilledCookIsRemoved) {
    // A real process that has exited: its pid is free.
    const pid_t dead = fork();
    if (dead == 0) _exit(0);
    waitpid(dead, nullptr, 0);
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    std::string h(host);
    for (char& ch : h)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    const std::string killed = ".atlas-staging-" + h + "-" + std::to_string(dead) + "-0123456789abcdef";
    const std::string alive = ".atlas-staging-" + h + "-" + std::to_string(::getpid()) + "-0123456789abcdef";
    // Folders of today's Atlas: their marker is locked while the cook runs. One held by a
    // cook in another PID namespace (its PID here names a dead process) is kept; one no
    // process holds is removed, whatever PID its name gives.
    const std::string held = ".atlas-staging-" + h + "-" + std::to_string(dead) + "-1111111111111111";
    const std::string unheld = ".atlas-staging-" + h + "-" + std::to_string(::getpid()) + "-2222222222222222";
    const std::string locked_marker = "atlas staging folder, locked while its cook runs; removed or completed by the next Atlas run\n";
    std::vector<int> locks;
    for (const fs::path& root : {dir / "out", dir / "cache"}) {
        // An older Atlas's folders (a marker without the lock), a minute old: by host and PID.
        fs::create_directories(root / killed / "nvdf");
        std::ofstream(root / killed / "nvdf" / "big.tga") << std::string(10000, 'k');
        std::ofstream(root / killed / ".atlas-staging") << "atlas staging folder"; // Atlas's marker: only marked folders are removed
        fs::create_directories(root / alive);
        std::ofstream(root / alive / ".atlas-staging") << "atlas staging folder";
        for (const std::string& f : {killed, alive})
            fs::last_write_time(root / f / ".atlas-staging", fs::file_time_type::clock::now() - std::chrono::minutes(5));
        for (const std::string& f : {held, unheld}) {
            fs::create_directories(root / f);
            std::ofstream(root / f / ".atlas-staging") << locked_marker;
        }
        const int fd = ::open((root / held / ".atlas-staging").c_str(), O_RDONLY);
        ASSERT_GE(fd, 0);
        ASSERT_EQ(::flock(fd, LOCK_SH), 0);
        locks.push_back(fd);
    }
    CookOptions o = options();
    o.cache_dir = dir / "cache";
    session().cook(o);
    for (const fs::path& root : {dir / "out", dir / "cache"}) {
        EXPECT_FALSE(fs::exists(root / killed)) << root;
        EXPECT_TRUE(fs::exists(root / alive)) << root;
        EXPECT_TRUE(fs::exists(root / held)) << root;
        EXPECT_FALSE(fs::exists(root / unheld)) << root;
    }
    // Its cook ends (the lock dies with the process): the next cook removes it.
    for (int fd : locks) ::close(fd);
    session().cook(o);
    for (const fs::path& root : {dir / "out", dir / "cache"}) EXPECT_FALSE(fs::exists(root / held)) << root;
}

// Inputs a node reads (through hash_file) are listed with their hashes; a
// failed cook still leaves a result naming the node and its line.
TEST_F(Fixture, ReportListsInputsAndFailures) {
    CookOptions o = options();
    session(kTwoOutputs).cook(o); // writes out/a.exr, an input for the next graph
    const std::string g = "atlas: 1\nnodes:\n  in:\n    type: import/exr\n    params: {file: out/a.exr}\noutputs:\n  - {node: in, file: copy.exr}\n";
    CookOptions o2 = o;
    o2.out_dir = dir / "out2";
    CookResult r = session(g).cook(o2);
    ASSERT_EQ(r.inputs.size(), 1u);
    EXPECT_EQ(r.inputs[0].path, dir / "out" / "a.exr");
    EXPECT_EQ(r.inputs[0].node, "in");
    EXPECT_EQ(r.inputs[0].hash, file_content_hash(dir / "out" / "a.exr").hex());
    const auto deps = r.depends("g.yaml");
    ASSERT_EQ(deps.size(), 2u);
    EXPECT_EQ(deps[1], dir / "out" / "a.exr");
    auto j = nlohmann::json::parse(r.to_json("g.yaml"));
    EXPECT_EQ(j["status"], "ok");
    EXPECT_EQ(j["inputs"][0]["hash"], r.inputs[0].hash);
    EXPECT_EQ(j["outputs"][0]["files"][0]["hash"], file_content_hash(dir / "out2" / "copy.exr").hex());

    Session s = session();
    log->fail = true;
    EXPECT_THROW(s.cook(options()), Error);
    const CookResult& f = s.last_result();
    EXPECT_EQ(f.status, "failed");
    EXPECT_EQ(f.error_node, "gate");
    EXPECT_EQ(f.error_where, "test.yaml:14:3");
    EXPECT_EQ(f.nodes.at("gate").status, "failed");
    EXPECT_NE(f.error.find("simulated failure"), std::string::npos);
    auto jf = nlohmann::json::parse(f.to_json("test.yaml"));
    EXPECT_EQ(jf["status"], "failed");
    EXPECT_EQ(jf["error"]["node"], "gate");
    EXPECT_EQ(jf["error"]["where"], "test.yaml:14:3");
}

// DDS textures are costly to encode: their files are kept in the disk cache
// by output key, so a deleted texture comes back without cooking or encoding.
TEST_F(Fixture, EncodedTextureIsRestoredFromTheCache) {
    const char* g = "atlas: 1\nnodes:\n  a:\n    type: test/source\n    params: {value: 0.5}\noutputs:\n"
                    "  - {node: a, file: a.dds, options: {encoding: bc4}}\n";
    CookOptions o = options();
    o.cache_dir = dir / "cache";
    CookResult r1 = session(g).cook(o);
    const std::string good = slurp(dir / "out" / "a.dds");
    fs::remove(dir / "out" / "a.dds");
    fs::remove(dir / "out" / "a.dds.json");
    // Nothing may cook or load: remove the node entries.
    for (const auto& e : fs::directory_iterator(dir / "cache"))
        if (e.path().extension() == ".atlascache") fs::remove(e.path());
    CookResult r2 = session(g).cook(o);
    EXPECT_EQ(log->count("a"), 1);
    EXPECT_EQ(output_named(r2, "a.dds").status, "restored");
    EXPECT_EQ(slurp(dir / "out" / "a.dds"), good);
    EXPECT_TRUE(fs::exists(dir / "out" / "a.dds.json"));
    EXPECT_EQ(output_named(r2, "a.dds").metrics, output_named(r1, "a.dds").metrics);
}

// A change upstream that leaves an output's value as it was (here a salt that
// changes the node's hash, not its value) cooks, but writes nothing.
TEST_F(Fixture, RecookedButUnchangedValueIsNotRewritten) {
    CookOptions o = options();
    session().cook(o);
    const fs::path gate = dir / "out" / "sub" / "gate.exr";
    const int64_t t = mtime_ns(gate);
    Session s = session();
    s.set_text("gate", "salt", "7");
    CookResult r = s.cook(o);
    EXPECT_EQ(r.nodes.at("gate").status, "cooked");
    EXPECT_EQ(output_named(r, "sub/gate.exr").status, "up to date");
    EXPECT_EQ(mtime_ns(gate), t);
    // The record now carries the new key: the next cook needs nothing.
    Session s2 = session();
    s2.set_text("gate", "salt", "7");
    CookResult r2 = s2.cook(o);
    EXPECT_EQ(r2.nodes.at("gate").status, "skipped");
    // A changed value is written.
    Session s3 = session();
    s3.set_text("a", "value", "9");
    EXPECT_EQ(output_named(s3.cook(o), "sub/gate.exr").status, "written");
    EXPECT_NE(mtime_ns(gate), t);
}

// A commit that cannot complete (a path component is a file) changes nothing:
// the other outputs keep their old files, no staging folder remains.
TEST_F(Fixture, FailedCommitLeavesNothingPartial) {
    fs::create_directories(dir / "out");
    { std::ofstream(dir / "out" / "a.exr") << "old a"; }
    { std::ofstream(dir / "out" / "sub") << "a file where a directory should be"; }
    Session s = session(kTwoOutputs); // writes a.exr and sub/b.png
    EXPECT_THROW(s.cook(options()), Error);
    EXPECT_EQ(slurp(dir / "out" / "a.exr"), "old a");
    EXPECT_EQ(slurp(dir / "out" / "sub"), "a file where a directory should be");
    for (const auto& e : fs::directory_iterator(dir / "out"))
        EXPECT_EQ(e.path().filename().string().find(".atlas-staging"), std::string::npos) << e.path();
    EXPECT_EQ(s.last_result().status, "failed");
}

// The cache's checksum depends only on the bytes (not on how they are fed)
// and sees every single-bit change.
TEST(ContentHasher, SplitIndependentAndBitSensitive) {
    std::string bytes(1000, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 7 + 3);
    const Hash128 whole = ContentHasher().add(bytes.data(), bytes.size()).finish();
    for (size_t cut : {0, 1, 31, 32, 33, 500, 999, 1000}) {
        ContentHasher h;
        h.add(bytes.data(), cut).add(bytes.data() + cut, bytes.size() - cut);
        EXPECT_EQ(h.finish(), whole) << cut;
    }
    for (size_t bit = 0; bit < bytes.size() * 8; bit += 37) {
        std::string b = bytes;
        b[bit / 8] ^= char(1 << (bit % 8));
        EXPECT_NE(ContentHasher().add(b.data(), b.size()).finish(), whole) << bit;
    }
    EXPECT_NE(ContentHasher().add(bytes.data(), 999).finish(), ContentHasher().add((bytes.substr(0, 999) + '\0').data(), 1000).finish());
}

// A damaged header claiming absurd dimensions is a miss, not an exception or
// an allocation of what it claims. (The input cache_entry_fuzz found, which
// threw std::length_error, is tests/fuzz/corpus/cache_entry_fuzz/
// regress_huge_resolution; the fuzz smoke run replays it.)
TEST(DiskCache, AbsurdDimensionsAreAMiss) {
    auto u64 = [](std::string& s, uint64_t v) { s.append(reinterpret_cast<const char*>(&v), 8); };
    for (uint64_t dim : {uint64_t(0), uint64_t(1) << 31, ~uint64_t(0), uint64_t(1) << 20, (uint64_t(1) << 55) | 4}) {
        std::string b = std::string("ATLASCACHE\x02", 11);
        u64(b, 1);
        u64(b, 3);
        b += "out";
        u64(b, 2); // a Field3D
        for (int k = 0; k < 3; ++k) u64(b, dim);
        for (int k = 0; k < 3; ++k) {
            const double lo = 0, hi = 1;
            b.append(reinterpret_cast<const char*>(&lo), 8).append(reinterpret_cast<const char*>(&hi), 8);
        }
        u64(b, 1); // one channel
        b += std::string(200, '\0');
        std::string why;
        EXPECT_FALSE(disk_cache::deserialize(b, &why).has_value()) << dim;
        EXPECT_FALSE(why.empty());
    }
}

// Errors raised while cooking carry the node's place in the graph file.
TEST_F(Fixture, CookErrorsCarryTheNodesFileLine) {
    Session s = session();
    log->fail = true;
    try {
        s.cook(options());
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("test.yaml:14:3: node 'gate' (test/fail): ", 0), 0u) << e.what();
    }
}

// An input that is not a regular file (a device, a FIFO) would never end:
// refused at once, naming the file.
TEST_F(Fixture, NonRegularInputFilesAreRefused) {
    const fs::path fifo = dir / "pipe.exr";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    for (const std::string& f : {std::string("/dev/zero"), fifo.string()}) {
        const std::string g = "atlas: 1\nnodes:\n  i:\n    type: import/exr\n    params: {file: " + f + "}\noutputs:\n  - {node: i, file: c.exr}\n";
        try {
            session(g).cook(options());
            FAIL() << f;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(f + ": not a regular file"), std::string::npos) << e.what();
        }
    }
}

TEST_F(Fixture, SetTimeRecooksOnlyWhatReadsAKeyedParameter) {
    Session s = session(R"(atlas: 1
time: {start: 0, end: 20, fps: 0.1}
nodes:
  a:
    type: test/source
    params: {value: {keys: [[0, 1], [20, 3]]}}
  b:
    type: test/source
    params: {value: 3}
  sum:
    type: test/add
    inputs: {a: a, b: b}
outputs:
  - {node: sum, file: sum.exr}
)");
    CookOptions o = writing_options();
    o.cache_dir = dir / "cache";
    s.cook(o);
    s.set_time(10);
    CookResult r = s.cook(o);
    EXPECT_EQ(r.with_status("cooked"), (std::vector<std::string>{"a", "sum"}));
    EXPECT_EQ(r.nodes.at("b").status, "cached");
    EXPECT_EQ(std::get<double>(s.graph().find("a")->params.at("value").value), 2.0);
    // Back at a time already cooked: from the disk cache, nothing cooks.
    s.set_time(0);
    EXPECT_TRUE(s.cook(o).with_status("cooked").empty());
    EXPECT_THROW(s.set_time(std::numeric_limits<double>::infinity()), Error);
}
