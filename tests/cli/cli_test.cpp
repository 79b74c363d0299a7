// The atlas program as users and scripts see it: exit status, stdout for data,
// stderr for messages, located errors, and the generated node reference.
#include "atlas/graph/node.h"
#include "atlas/graph/node_docs.h"
#include "atlas/core/files.h"
#include "atlas/compress/texture.h"
#include "atlas/io/dds_file.h"

#include "../support/cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <csignal>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using atlas::test::CliRun;

CliRun run(const std::string& args) {
    const fs::path dir = atlas::test::process_dir("atlas_cli_test");
    return atlas::test::run_shell(atlas::test::atlas_program() + " " + args + " 2>" + (dir / "err").string(), dir / "err");
}

fs::path write_graph(const std::string& name, const std::string& text) {
    fs::path dir = fs::temp_directory_path() / ("atlas_cli_graphs_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / name) << text;
    return dir / name;
}

} // namespace

TEST(Cli, NodesListGoesToStdout) {
    CliRun r = run("nodes");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("noise/value"), std::string::npos);
    EXPECT_NE(r.out.find("math/remap"), std::string::npos);
    EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(Cli, NodeReferenceShowsParameters) {
    CliRun r = run("nodes math/remap");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("in_min (float) = 0"), std::string::npos) << r.out;
    CliRun bad = run("nodes math/remapp");
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.err.find("did you mean 'math/remap'?"), std::string::npos) << bad.err;
}

TEST(Cli, DocsNodesMdIsUpToDate) {
    std::string expected = atlas::node_reference_markdown(atlas::builtin_nodes());
    std::string actual;
    ASSERT_NO_THROW(actual = atlas::read_file_bytes(std::string(ATLAS_SOURCE_DIR) + "/docs/nodes.md"));
    EXPECT_TRUE(actual == expected)
        << "docs/nodes.md is stale: regenerate it with 'build/bin/atlas nodes --markdown > docs/nodes.md'";
}

TEST(Cli, ValidateReportsLocatedErrors) {
    auto g = write_graph("typo.yaml", "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params:\n      octavs: 3\noutputs: []\n");
    CliRun r = run("validate " + g.string());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find(g.string() + ":6:7: error: node 'n': unknown parameter 'octavs' (did you mean 'octaves'?)"), std::string::npos)
        << r.err;
    EXPECT_TRUE(r.out.empty());
}

TEST(Cli, ValidateWarnsOfMissingInputFiles) {
    // A graph reading a file nothing has written yet is well formed (exit 0), but validate says
    // the cook will fail (cumulus_cloudscape.yaml on a fresh clone read as "ok").
    auto g = write_graph("reads.yaml", "atlas: 1\nnodes:\n  tower:\n    type: import/vdb\n    params:\n      file: not_yet/cloud.vdb\noutputs: []\n");
    CliRun r = run("validate " + g.string());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("1 input file(s) missing"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find(g.string() + ":6: warning: node 'tower' (import/vdb) parameter 'file': "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("does not exist: the cook will fail unless something writes it first"), std::string::npos) << r.err;
    // Once the file exists, nothing is said.
    fs::create_directories(g.parent_path() / "not_yet");
    std::ofstream(g.parent_path() / "not_yet" / "cloud.vdb") << "x";
    CliRun ok = run("validate " + g.string());
    EXPECT_EQ(ok.status, 0);
    EXPECT_EQ(ok.out.find("missing"), std::string::npos) << ok.out;
    EXPECT_EQ(ok.err.find("warning"), std::string::npos) << ok.err;
}

TEST(Cli, CookCooksTheGraphsItRequiresFirst) {
    // A graph that reads another graph's output declares it (requires:): on a fresh clone the
    // cook grows the input first, validate says so, and a present input is not cooked again.
    const fs::path dir = fs::temp_directory_path() / ("atlas_cli_requires_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "maker.yaml") << "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [8, 8, 8], bounds_max: [80, 80, 80]}\n"
                                         "outputs:\n  - {node: n, file: cloud.vdb}\n";
    std::ofstream(dir / "reader.yaml") << "atlas: 1\nrequires:\n  - {graph: maker.yaml, out: made}\nnodes:\n  in:\n    type: import/vdb\n"
                                          "    params: {file: made/cloud.vdb, grids: density}\n  r:\n    type: math/remap\n    inputs: {in: in}\n"
                                          "outputs:\n  - {node: r, file: r.exr}\n";
    CliRun v = run("validate " + (dir / "reader.yaml").string());
    EXPECT_EQ(v.status, 0) << v.err;
    EXPECT_NE(v.err.find("`atlas cook` will cook " + (dir / "maker.yaml").string() + " into " + (dir / "made").string() + " first"), std::string::npos)
        << v.err;
    CliRun c = run("cook " + (dir / "reader.yaml").string() + " --out " + (dir / "out").string() + " --no-cache --report " + (dir / "r.json").string());
    ASSERT_EQ(c.status, 0) << c.err;
    EXPECT_NE(c.err.find("reads files " + (dir / "maker.yaml").string() + " writes: cooking it into " + (dir / "made").string() + " first"),
              std::string::npos) << c.err;
    EXPECT_TRUE(fs::exists(dir / "made" / "cloud.vdb"));
    EXPECT_TRUE(fs::exists(dir / "out" / "r.exr"));
    nlohmann::json report = nlohmann::json::parse(std::ifstream(dir / "r.json"));
    ASSERT_TRUE(report.contains("graphs")) << report.dump(); // both cooks in one report
    EXPECT_EQ(report["graphs"].size(), 2u);
    // Present now: not cooked again.
    CliRun again = run("cook " + (dir / "reader.yaml").string() + " --out " + (dir / "out").string() + " --no-cache");
    ASSERT_EQ(again.status, 0) << again.err;
    EXPECT_EQ(again.err.find("cooking it into"), std::string::npos) << again.err;
    // A cycle is refused with the requirement's line.
    std::ofstream(dir / "a.yaml") << "atlas: 1\nrequires:\n  - {graph: b.yaml, out: bo}\nnodes:\n  in:\n    type: import/vdb\n"
                                     "    params: {file: bo/x.vdb}\noutputs:\n  - {node: in, file: a.vdb}\n";
    std::ofstream(dir / "b.yaml") << "atlas: 1\nrequires:\n  - {graph: a.yaml, out: ao}\nnodes:\n  in:\n    type: import/vdb\n"
                                     "    params: {file: ao/a.vdb}\noutputs:\n  - {node: in, file: x.vdb}\n";
    CliRun cyc = run("cook " + (dir / "a.yaml").string() + " --out " + (dir / "out").string() + " --no-cache");
    EXPECT_EQ(cyc.status, 1);
    EXPECT_NE(cyc.err.find("b.yaml:3:5: error: requirement '" + (dir / "a.yaml").string() + "' leads back to a graph that requires it (a cycle)"),
              std::string::npos) << cyc.err;
    // A malformed requirement names what is expected.
    std::ofstream(dir / "bad.yaml") << "atlas: 1\nrequires:\n  - {graph: maker.yaml}\nnodes: {}\noutputs: []\n";
    CliRun bad = run("validate " + (dir / "bad.yaml").string());
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.err.find("bad.yaml:3:5: error: requirement: missing 'out'"), std::string::npos) << bad.err;
    fs::remove_all(dir);
}

TEST(Cli, UsageErrorsExitTwo) {
    CliRun r = run("cook --jbos 2 x.yaml");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("unknown option '--jbos' for 'atlas cook' (did you mean '--jobs'?)"), std::string::npos) << r.err;
    EXPECT_EQ(run("frobnicate").status, 2);
    EXPECT_EQ(run("cook").status, 2);
}

// The help text and the missing-format message name every format the library takes.
TEST(Cli, CompressNamesEveryFormat) {
    const std::string names = atlas::compress::format_names();
    CliRun help = run("compress --help");
    CliRun missing = run("compress in.exr -o out.dds");
    EXPECT_EQ(missing.status, 2);
    size_t start = 0;
    while (start < names.size()) {
        size_t end = names.find(", ", start);
        if (end == std::string::npos) end = names.size();
        const std::string name = names.substr(start, end - start);
        EXPECT_NE((help.out + help.err).find(name), std::string::npos) << "help lacks " << name;
        EXPECT_NE(missing.err.find(name), std::string::npos) << "message lacks " << name;
        start = end + 2;
    }
}

TEST(Cli, MissingGraphFileIsNamed) {
    CliRun r = run("cook /nonexistent/graph.yaml");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("/nonexistent/graph.yaml: cannot read graph file"), std::string::npos) << r.err;
}

TEST(Cli, CookWritesSummaryAndFilesAndReport) {
    auto g = write_graph("small.yaml", R"(atlas: 1
nodes:
  n:
    type: noise/value
    params: {resolution: [16, 16, 4]}
  unused:
    type: noise/value
outputs:
  - {node: n, file: n.exr}
  - {node: n, file: n.png, options: {slice: 1}}
)");
    fs::path out = fs::temp_directory_path() / ("atlas_cli_out_" + std::to_string(::getpid()));
    fs::remove_all(out);
    CliRun r = run("cook " + g.string() + " --out " + out.string() + " --report " + (out / "r.json").string() + " --quiet --jobs 2");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("cooked 1, cached 0, skipped 1 nodes"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find((out / "n.exr").string()), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(out / "n.exr"));
    EXPECT_TRUE(fs::exists(out / "n.png"));
    EXPECT_TRUE(fs::exists(out / "r.json"));
    EXPECT_TRUE(r.err.empty()) << r.err;

    CliRun info = run("info " + (out / "n.exr").string());
    EXPECT_EQ(info.status, 0) << info.err;
    EXPECT_NE(info.out.find("3D field 16x16x4"), std::string::npos) << info.out;

    CliRun set = run("cook " + g.string() + " --out " + out.string() + " --set n.octaves=99 --quiet");
    EXPECT_EQ(set.status, 1);
    EXPECT_NE(set.err.find("--set n.octaves=99: node 'n': parameter 'octaves' (int): value 99 is out of range [1, 16]"),
              std::string::npos) << set.err;
    fs::remove_all(out);
}

TEST(Cli, CompressInfoDecompressRoundTrip) {
    auto g = write_graph("tex.yaml", R"(atlas: 1
nodes:
  n:
    type: noise/value
    params: {resolution: [16, 16, 2], octaves: 2}
outputs:
  - {node: n, file: n.exr}
)");
    fs::path out = fs::temp_directory_path() / ("atlas_cli_tex_" + std::to_string(::getpid()));
    fs::remove_all(out);
    ASSERT_EQ(run("cook " + g.string() + " --out " + out.string() + " --quiet").status, 0);
    CliRun c = run("compress " + (out / "n.exr").string() + " --format bc4 --one-sided below -o " + (out / "n.dds").string() +
                   " --quiet --report " + (out / "n.json").string());
    ASSERT_EQ(c.status, 0) << c.err;
    EXPECT_NE(c.out.find("bc4 16x16x2"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("verify"), std::string::npos) << "a bounded encode verifies by default\n" << c.out;
    EXPECT_TRUE(fs::exists(out / "n.dds.json"));
    EXPECT_TRUE(fs::exists(out / "n.json"));
    CliRun i = run("info " + (out / "n.dds").string());
    EXPECT_EQ(i.status, 0) << i.err;
    EXPECT_NE(i.out.find("3D field 16x16x2"), std::string::npos) << i.out;
    CliRun d = run("decompress " + (out / "n.dds").string() + " -o " + (out / "back.exr").string());
    EXPECT_EQ(d.status, 0) << d.err;
    EXPECT_TRUE(fs::exists(out / "back.exr"));
    CliRun bad = run("compress " + (out / "n.exr").string() + " --format bc9 -o " + (out / "x.dds").string());
    EXPECT_EQ(bad.status, 2); // a usage error, as every value the option schema refuses
    EXPECT_NE(bad.err.find("--format expects"), std::string::npos) << bad.err;
    EXPECT_FALSE(fs::exists(out / "x.dds"));
    fs::remove_all(out);
}

// What an engine or a texture artist sees: OpenImageIO (oiiotool), not Atlas's own
// decoder, reads the DDS files `atlas compress` writes. `oiiotool --diff` exits
// non-zero when two images differ by more than --fail anywhere.
namespace {
int sh(const std::string& cmd) {
    const int st = std::system((cmd + " >/dev/null 2>&1").c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
} // namespace

TEST(CliForeign, DdsShowsWhatThePngShows) {
    fs::path dir = fs::temp_directory_path() / ("atlas_cli_orient_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string in = (dir / "in.png").string();
    // Four different corners: any flip or transpose changes the picture.
    ASSERT_EQ(sh("oiiotool --pattern fill:topleft=1,0,0:topright=0,1,0:bottomleft=0,0,1:bottomright=1,1,1 32x16 3 -d uint8 -o " + in), 0);
    // OIIO 2.4 reads 2D BC1 and BC4 DDS files (BC4 as one channel it names Y: compare channel 0).
    for (const std::string fmt : {"bc1", "bc4"}) {
        const std::string ch = fmt == "bc1" ? "R,G,B" : "0";
        const std::string dds = (dir / ("a_" + fmt + ".dds")).string(), back = (dir / ("back_" + fmt + ".png")).string(),
                          ref = (dir / ("ref_" + fmt + ".png")).string(), flipped = (dir / "flipped.png").string();
        CliRun c = run("compress " + in + " --format " + fmt + " --range 0,1 --quiet -o " + dds);
        ASSERT_EQ(c.status, 0) << c.err;
        ASSERT_EQ(sh("oiiotool " + in + " --ch " + ch + " -o " + ref), 0);
        ASSERT_EQ(sh("oiiotool " + dds + " --ch " + ch + " -d uint8 -o " + back), 0) << fmt;
        EXPECT_EQ(sh("oiiotool --fail 0.1 --diff " + ref + " " + back), 0) << fmt << ": OpenImageIO shows the DDS differently from the PNG";
        // The check can fail: the same picture upside down does.
        ASSERT_EQ(sh("oiiotool " + back + " --flip -o " + flipped), 0);
        EXPECT_NE(sh("oiiotool --fail 0.1 --diff " + ref + " " + flipped), 0);
    }
    fs::remove_all(dir);
}

TEST(CliForeign, RgbExrFromAnotherToolKeepsRedInRed) {
    fs::path dir = fs::temp_directory_path() / ("atlas_cli_rgbexr_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string exr = (dir / "in.exr").string(), ref = (dir / "ref.png").string(), dds = (dir / "a.dds").string(),
                      back = (dir / "back.png").string();
    // OpenEXR lists these channels as B, G, R.
    ASSERT_EQ(sh("oiiotool --pattern fill:top=0.9,0.2,0.05:bottom=0.8,0.3,0.1 16x16 3 -d float -o " + exr), 0);
    ASSERT_EQ(sh("oiiotool " + exr + " -d uint8 -o " + ref), 0);
    CliRun c = run("compress " + exr + " --format bc1 --range 0,1 --quiet -o " + dds);
    ASSERT_EQ(c.status, 0) << c.err;
    ASSERT_EQ(sh("oiiotool " + dds + " --ch R,G,B -d uint8 -o " + back), 0);
    EXPECT_EQ(sh("oiiotool --fail 0.06 --diff " + ref + " " + back), 0) << "BC1 of an RGB EXR does not look like the EXR";
    fs::remove_all(dir);
}

TEST(CliForeign, DecompressRestoresWorldBounds) {
    auto g = write_graph("bounds.yaml", R"(atlas: 1
nodes:
  n:
    type: noise/value
    params: {resolution: [16, 8, 2], octaves: 2, bounds_min: [-2000, 500, 0], bounds_max: [6000, 4500, 512]}
outputs:
  - {node: n, file: n.exr}
)");
    fs::path out = fs::temp_directory_path() / ("atlas_cli_bounds_" + std::to_string(::getpid()));
    fs::remove_all(out);
    ASSERT_EQ(run("cook " + g.string() + " --out " + out.string() + " --quiet").status, 0);
    ASSERT_EQ(run("compress " + (out / "n.exr").string() + " --format bc4 --quiet -o " + (out / "n.dds").string()).status, 0);
    CliRun d = run("decompress " + (out / "n.dds").string() + " -o " + (out / "back.exr").string());
    ASSERT_EQ(d.status, 0) << d.err;
    // oiiotool prints the EXR's atlas:bounds attributes; both files must carry the same.
    auto bounds_lines = [](const fs::path& p) {
        FILE* f = popen(("oiiotool --info -v " + p.string() + " 2>&1 | grep atlas:bounds").c_str(), "r");
        std::string s;
        std::array<char, 512> buf;
        size_t n;
        while ((n = fread(buf.data(), 1, buf.size(), f)) > 0) s.append(buf.data(), n);
        pclose(f);
        return s;
    };
    const std::string a = bounds_lines(out / "n.exr"), b = bounds_lines(out / "back.exr");
    EXPECT_NE(a.find("-2000"), std::string::npos) << a;
    EXPECT_EQ(a, b);
    fs::remove_all(out);
}

TEST(CliForeign, CompressHelpNamesEveryDecoder) {
    CliRun help = run("compress --help");
    const std::string text = help.out + help.err;
    for (int i = 0; i < atlas::compress::kDecoderCount; ++i) {
        const std::string name = atlas::compress::decoder_name(static_cast<atlas::compress::Decoder>(i));
        EXPECT_NE(text.find("'" + name + "'"), std::string::npos) << name << " is missing from:\n" << text;
    }
}

// ------------------------------------------------- unattended cooks (issue 17)

namespace {
// Runs atlas with a file-size limit (RLIMIT_FSIZE, SIGXFSZ ignored): every
// write past `max_file_bytes` fails with EFBIG, as on a full disk.
CliRun run_limited(const std::string& args, long max_file_bytes) {
    fs::path dir = fs::temp_directory_path() / ("atlas_cli_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string cmd = std::string(ATLAS_BINARY_DIR) + "/bin/atlas " + args + " >" + (dir / "out").string() + " 2>" + (dir / "err").string();
    const pid_t pid = fork();
    if (pid == 0) {
        signal(SIGXFSZ, SIG_IGN);
        struct rlimit lim{rlim_t(max_file_bytes), rlim_t(max_file_bytes)};
        setrlimit(RLIMIT_FSIZE, &lim);
        execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    CliRun r;
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.out = atlas::read_file_bytes(dir / "out");
    r.err = atlas::read_file_bytes(dir / "err");
    return r;
}

fs::path fresh_dir(const std::string& name) {
    fs::path d = fs::temp_directory_path() / ("atlas_cli_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// Every regular file under `d`, relative, except the output records.
std::vector<std::string> files_under(const fs::path& d) {
    std::vector<std::string> v;
    if (!fs::exists(d)) return v;
    for (const auto& e : fs::recursive_directory_iterator(d))
        if (e.is_regular_file() && e.path().filename() != ".atlas-outputs.json") v.push_back(fs::relative(e.path(), d).string());
    std::sort(v.begin(), v.end());
    return v;
}

const char* kNoiseGraph = "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [64, 64, 16], seed: 3}\noutputs:\n";
} // namespace

// On a full disk (here a file-size limit) PNG, VDB, TGA slice and EXR outputs
// fail loudly and leave nothing behind: no partial file, no staging folder.
TEST(CliUnattended, FullDiskFailsLoudlyAndLeavesNoPartialFile) {
    const std::vector<std::pair<std::string, std::string>> outputs = {
        {"png", "  - {node: n, file: pic.png, options: {montage: true, bits: 16}}\n"},
        {"vdb", "  - {node: n, file: v.vdb}\n"},
        {"tga-slices", "  - {node: n, file: s/stack, format: tga-slices, options: {compression: none}}\n"},
        {"exr", "  - {node: n, file: v.exr}\n"},
        // Two frames of one grid each, named as sim/cloud_growth's sequence names them.
        {"vdb-sequence", "  - {node: seq, file: frames/f, format: vdb-sequence}\n"},
    };
    for (const auto& [fmt, line] : outputs) {
        const fs::path d = fresh_dir("fulldisk");
        std::string graph = kNoiseGraph;
        if (fmt == "vdb-sequence")
            graph.insert(graph.find("outputs:"), "  seq:\n    type: field/pack\n    inputs: {r: n, g: n}\n    params: {names: '0000:density,0001:density'}\n");
        auto g = write_graph("full_" + fmt + ".yaml", graph + line);
        // Without the limit the cook succeeds (the test can fail for the right reason).
        CliRun ok = run("cook " + g.string() + " --out " + (d / "ok").string() + " --no-cache --quiet");
        ASSERT_EQ(ok.status, 0) << fmt << ": " << ok.err;
        CliRun r = run_limited("cook " + g.string() + " --out " + (d / "out").string() + " --no-cache --quiet", 12000);
        EXPECT_EQ(r.status, 1) << fmt << ": " << r.err;
        EXPECT_NE(r.err.find("error"), std::string::npos) << fmt << ": " << r.err;
        EXPECT_EQ(r.out, "") << fmt; // no success line
        EXPECT_TRUE(files_under(d / "out").empty()) << fmt << ": " << ::testing::PrintToString(files_under(d / "out"));
        if (fs::exists(d / "out")) {
            for (const auto& e : fs::directory_iterator(d / "out"))
                EXPECT_EQ(e.path().filename().string().find(".atlas-staging"), std::string::npos) << fmt << ": " << e.path();
        }
    }
}

// A cache on a full disk costs speed, not the cook: a warning, outputs written.
TEST(CliUnattended, FullCacheDiskDegradesToCookingWithoutTheCache) {
    const fs::path d = fresh_dir("fullcache");
    // The 3D field's cache entry (256 KiB) is past the limit; the small JSON output is not.
    auto g = write_graph("fullcache.yaml", "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [64, 64, 16]}\n"
                                           "  s:\n    type: field/resample\n    inputs: {in: n}\n    params: {resolution: [4, 4, 1]}\n"
                                           "outputs:\n  - {node: s, file: s.exr}\n");
    CliRun r = run_limited("cook " + g.string() + " --out " + (d / "out").string() + " --cache " + (d / "cache").string(), 40000);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning: disk cache: cannot store node 'n'"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(d / "out" / "s.exr"));
}

// The depfile names every output file as a target and the graph and every
// file it reads as prerequisites, in Make syntax.
TEST(CliUnattended, DepfileListsGraphAndInputs) {
    const fs::path d = fresh_dir("depfile");
    auto src = write_graph("dep_src.yaml", std::string(kNoiseGraph) + "  - {node: n, file: in.exr}\n");
    ASSERT_EQ(run("cook " + src.string() + " --out " + d.string() + " --quiet").status, 0);
    auto g = write_graph("dep use.yaml", "atlas: 1\nnodes:\n  i:\n    type: import/exr\n    params: {file: " + (d / "in.exr").string() +
                                             "}\noutputs:\n  - {node: i, file: copy.exr}\n  - {node: i, file: st/copy, format: tga-slices}\n");
    CliRun r = run("cook '" + g.string() + "' --out " + (d / "o").string() + " --depfile " + (d / "cook.d").string() + " --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string dep = atlas::read_file_bytes(d / "cook.d");
    const std::string escaped_graph = (g.parent_path() / "dep\\ use.yaml").string();
    EXPECT_EQ(dep.find((d / "o" / "copy.exr").string()), 0u) << dep;
    EXPECT_NE(dep.find((d / "o" / "st" / "copy.001.tga").string()), std::string::npos) << dep;
    EXPECT_NE(dep.find("copy.016.tga"), std::string::npos) << dep;
    const auto colon = dep.find(':');
    EXPECT_GT(dep.find(escaped_graph), colon) << dep;
    EXPECT_GT(dep.find((d / "in.exr").string()), colon) << dep;
    // A second, no-op cook gives the same depfile (outputs up to date are still its targets).
    ASSERT_EQ(run("cook '" + g.string() + "' --out " + (d / "o").string() + " --depfile " + (d / "cook2.d").string() + " --quiet").status, 0);
    EXPECT_EQ(atlas::read_file_bytes(d / "cook2.d"), dep);
}

// A failed cook still writes its report (status, error, node, file:line) and exits 1.
TEST(CliUnattended, FailedCookWritesAReport) {
    const fs::path d = fresh_dir("failreport");
    auto g = write_graph("fail.yaml", "atlas: 1\nnodes:\n  i:\n    type: import/exr\n    params: {file: missing.exr}\noutputs:\n"
                                      "  - {node: i, file: copy.exr}\n");
    CliRun r = run("cook " + g.string() + " --out " + d.string() + " --report " + (d / "r.json").string() + " --quiet");
    EXPECT_EQ(r.status, 1);
    const auto j = nlohmann::json::parse(atlas::read_file_bytes(d / "r.json"));
    EXPECT_EQ(j["status"], "failed");
    EXPECT_EQ(j["error"]["node"], "i");
    EXPECT_EQ(j["error"]["where"], g.string() + ":3:3");
    EXPECT_NE(j["error"]["message"].get<std::string>().find("missing.exr"), std::string::npos);
    // A graph that does not parse: the report names the place.
    auto bad = write_graph("bad.yaml", "atlas: 1\nnodes:\n  n:\n    type: noise/valu\noutputs: []\n");
    CliRun r2 = run("cook " + bad.string() + " --out " + d.string() + " --report " + (d / "r2.json").string() + " --quiet");
    EXPECT_EQ(r2.status, 1);
    const auto j2 = nlohmann::json::parse(atlas::read_file_bytes(d / "r2.json"));
    EXPECT_EQ(j2["status"], "failed");
    EXPECT_EQ(j2["error"]["where"], bad.string() + ":4:11");
}

// Several graphs in one call: one cache, one report; a no-op second call
// rewrites nothing (the files' mtimes stay).
TEST(CliUnattended, SeveralGraphsShareOneReportAndANoOpCookWritesNothing) {
    const fs::path d = fresh_dir("multi");
    auto g1 = write_graph("multi1.yaml", std::string(kNoiseGraph) + "  - {node: n, file: one.png, options: {slice: 2}}\n");
    auto g2 = write_graph("multi2.yaml", std::string(kNoiseGraph) + "  - {node: n, file: two.exr}\n");
    const std::string args = "cook " + g1.string() + " " + g2.string() + " --out " + (d / "o").string() + " --cache " + (d / "c").string() +
                             " --report " + (d / "r.json").string();
    CliRun r = run(args);
    ASSERT_EQ(r.status, 0) << r.err;
    auto j = nlohmann::json::parse(atlas::read_file_bytes(d / "r.json"));
    ASSERT_EQ(j["graphs"].size(), 2u);
    EXPECT_EQ(j["status"], "ok");
    EXPECT_EQ(j["graphs"][0]["nodes"]["n"]["status"], "cooked");
    EXPECT_EQ(j["graphs"][1]["nodes"]["n"]["status"], "cached"); // the same node content: from the shared cache
    const auto t1 = fs::last_write_time(d / "o" / "one.png"), t2 = fs::last_write_time(d / "o" / "two.exr");
    CliRun again = run(args);
    ASSERT_EQ(again.status, 0) << again.err;
    EXPECT_NE(again.out.find("cooked 0, cached 0, skipped 2 nodes"), std::string::npos) << again.out;
    EXPECT_NE(again.out.find("wrote 0 files"), std::string::npos) << again.out;
    EXPECT_EQ(fs::last_write_time(d / "o" / "one.png"), t1);
    EXPECT_EQ(fs::last_write_time(d / "o" / "two.exr"), t2);
    j = nlohmann::json::parse(atlas::read_file_bytes(d / "r.json"));
    EXPECT_EQ(j["graphs"][1]["outputs"][0]["status"], "up to date");
    EXPECT_EQ(j["graphs"][1]["outputs"][0]["files"][0]["hash"].get<std::string>().size(), 32u);
}

// Two cooks running at once with one cache directory both succeed with the
// same bytes (entries are written atomically; either one's is valid).
TEST(CliUnattended, TwoConcurrentCooksSharingACacheStayCorrect) {
    const fs::path d = fresh_dir("shared");
    auto g = write_graph("shared.yaml", "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [64, 64, 32]}\n"
                                        "  r:\n    type: math/remap\n    inputs: {in: n}\n    params: {in_min: 0.3, in_max: 0.7}\n"
                                        "outputs:\n  - {node: r, file: r.exr}\n");
    const std::string bin = std::string(ATLAS_BINARY_DIR) + "/bin/atlas";
    const std::string c = " --cache " + (d / "c").string() + " --quiet";
    const std::string cmd = bin + " cook " + g.string() + " --out " + (d / "a").string() + c + " & " + bin + " cook " + g.string() + " --out " +
                            (d / "b").string() + c + " & wait";
    ASSERT_EQ(std::system(("sh -c '" + cmd + "' >/dev/null 2>&1").c_str()), 0);
    ASSERT_TRUE(fs::exists(d / "a" / "r.exr"));
    ASSERT_TRUE(fs::exists(d / "b" / "r.exr"));
    EXPECT_EQ(atlas::read_file_bytes(d / "a" / "r.exr"), atlas::read_file_bytes(d / "b" / "r.exr"));
    // A third cook from the shared cache gives the same bytes again.
    ASSERT_EQ(run("cook " + g.string() + " --out " + (d / "x").string() + c).status, 0);
    EXPECT_EQ(atlas::read_file_bytes(d / "x" / "r.exr"), atlas::read_file_bytes(d / "a" / "r.exr"));
}

TEST(CliUnattended, CachePruneKeepsTheMostRecentlyUsed) {
    const fs::path d = fresh_dir("prune");
    auto g = write_graph("prune.yaml", std::string(kNoiseGraph) + "  - {node: n, file: n.exr}\n");
    ASSERT_EQ(run("cook " + g.string() + " --out " + (d / "o").string() + " --cache " + (d / "c").string() + " --quiet").status, 0);
    uint64_t before = 0;
    for (const auto& e : fs::directory_iterator(d / "c")) before += e.file_size();
    ASSERT_GT(before, 0u);
    CliRun keep = run("cache prune " + (d / "c").string() + " --max-size " + std::to_string(before));
    EXPECT_EQ(keep.status, 0) << keep.err;
    EXPECT_NE(keep.out.find("removed 0 entries"), std::string::npos) << keep.out;
    CliRun all = run("cache prune " + (d / "c").string() + " --max-size 0 --quiet");
    EXPECT_EQ(all.status, 0) << all.err;
    EXPECT_NE(all.out.find("removed 1 entries (" + std::to_string(before) + " bytes), 0 bytes left"), std::string::npos) << all.out;
    EXPECT_EQ(run("cache prune " + (d / "c").string()).status, 2); // --max-size is required
}

// `--out .` (or no --out) with output paths whose directories do not exist
// yet writes them, instead of refusing them as leaving the directory.
TEST(CliUnattended, OutDotWritesIntoNewDirectories) {
    const fs::path d = fresh_dir("outdot");
    auto g = write_graph("outdot.yaml", std::string(kNoiseGraph) + "  - {node: n, file: new/sub/n.exr}\n");
    const std::string bin = std::string(ATLAS_BINARY_DIR) + "/bin/atlas";
    const std::string cook = bin + " cook " + g.string() + " --quiet --no-cache";
    EXPECT_EQ(std::system(("cd " + d.string() + " && " + cook + " --out . >/dev/null").c_str()), 0);
    EXPECT_TRUE(fs::exists(d / "new" / "sub" / "n.exr"));
    fs::remove_all(d / "new");
    EXPECT_EQ(std::system(("cd " + d.string() + " && " + cook + " >/dev/null").c_str()), 0);
    EXPECT_TRUE(fs::exists(d / "new" / "sub" / "n.exr"));
}

// `atlas compress --mips` takes what the graph's dds option `mips` takes (issue 13:
// the CLI gave a full chain for 0, truncated 2.7 and accepted 17).
TEST(CliForeign, CompressMipsAgreesWithTheGraphOption) {
    fs::path dir = fs::temp_directory_path() / ("atlas_cli_mips_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto g = write_graph("mips.yaml", "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [32, 32, 1]}\noutputs:\n"
                                      "  - {node: n, file: n.exr}\n");
    ASSERT_EQ(run("cook " + g.string() + " --out " + dir.string() + " --quiet").status, 0);
    const std::string in = (dir / "n.exr").string();
    for (const std::string bad : {"0", "2.7", "17", "-1", "two", ""}) {
        CliRun c = run("compress " + in + " --format r8 --quiet --mips '" + bad + "' -o " + (dir / "x.dds").string());
        EXPECT_EQ(c.status, 2) << "--mips " << bad << " was accepted";
        EXPECT_NE(c.err.find("--mips expects an integer in [1, 16] or 'full'"), std::string::npos) << c.err;
        EXPECT_FALSE(fs::exists(dir / "x.dds"));
        // The graph's option refuses the same value (validate cooks nothing).
        auto gb = write_graph("mips_bad.yaml", "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [32, 32, 1]}\noutputs:\n"
                                               "  - {node: n, file: x.dds, options: {encoding: r8, mips: '" + bad + "'}}\n");
        EXPECT_NE(run("cook " + gb.string() + " --out " + (dir / "g").string() + " --quiet --no-cache").status, 0) << "graph mips " << bad;
    }
    for (const std::string good : {"1", "3", "full"}) {
        CliRun c = run("compress " + in + " --format r8 --quiet --mips " + good + " -o " + (dir / "y.dds").string());
        EXPECT_EQ(c.status, 0) << good << ": " << c.err;
        const atlas::compress::DdsTexture t = atlas::io::read_dds_file(dir / "y.dds");
        EXPECT_EQ(t.mip_levels, good == "full" ? 6 : std::stoi(good)) << good;
    }
    fs::remove_all(dir);
}

// Output option values are checked when the graph loads (issue 17 item 8,
// issue 13): `validate` names the option's file:line, and `cook` refuses
// before any node cooks (nothing written, no node in the report cooked).
TEST(CliManners, BadOptionValuesAreRefusedAtLoadWithTheirLine) {
    struct Case {
        std::string output, expect;
    };
    const std::vector<Case> cases = {
        {"{node: n, file: n.png, options: {bits: 12}}", "option 'bits': expected 8 or 16, got '12'"},
        {"{node: n, file: n.exr, options: {half: maybe}}", "option 'half': expected true or false"},
        {"{node: n, file: n.vdb, options: {tolerance: -1}}", "option 'tolerance'"},
        {"{node: n, file: n.dds, options: {encoding: bc9}}", "bc9"},
        {"{node: n, file: n.dds, options: {mips: 17}}", "option 'mips'"},
        {"{node: n, file: s/n, format: tga-slices, options: {naming: foo}}", "option 'naming'"},
        {"{node: n, file: n.png, options: {range: '1,0'}}", "option 'range'"},
        {"{node: n, file: n.png, options: {montage: true, slice: 2}}", "'montage' and 'slice' exclude each other"},
        {"{node: n, file: n.tga, options: {slice: -1}}", "option 'slice'"},
    };
    const fs::path d = fresh_dir("badopts");
    for (const auto& c : cases) {
        auto g = write_graph("badopt.yaml", std::string(kNoiseGraph) + "  - " + c.output + "\n");
        CliRun v = run("validate " + g.string());
        EXPECT_EQ(v.status, 1) << c.output;
        EXPECT_NE(v.err.find(g.string() + ":7:"), std::string::npos) << c.output << "\n" << v.err;
        EXPECT_NE(v.err.find(c.expect), std::string::npos) << c.output << "\n" << v.err;
        // Say "error" and the output's name once.
        EXPECT_EQ(v.err.find("error"), v.err.rfind("error")) << v.err;
        EXPECT_EQ(v.err.find("output '"), v.err.rfind("output '")) << v.err;
        CliRun k = run("cook " + g.string() + " --no-cache --quiet --out " + d.string() + " --report " + (d / "r.json").string());
        EXPECT_EQ(k.status, 1) << c.output;
        EXPECT_NE(k.err.find(c.expect), std::string::npos) << k.err;
        const auto j = nlohmann::json::parse(atlas::read_file_bytes(d / "r.json"));
        EXPECT_EQ(j["status"], "failed");
        EXPECT_EQ(j["summary"]["cooked"].get<int>(), 0) << c.output;
        fs::remove(d / "r.json");
        EXPECT_TRUE(files_under(d).empty()) << c.output;
    }
    // A value-dependent option (a channel the value lacks) is still a cook error, located.
    auto g = write_graph("badchan.yaml", std::string(kNoiseGraph) + "  - {node: n, file: n.exr, options: {channels: nope}}\n");
    EXPECT_EQ(run("validate " + g.string()).status, 0);
    CliRun k = run("cook " + g.string() + " --no-cache --quiet --out " + d.string());
    EXPECT_EQ(k.status, 1);
    EXPECT_NE(k.err.find(g.string() + ":7:"), std::string::npos) << k.err;
    EXPECT_EQ(k.err.find("output '"), k.err.rfind("output '")) << k.err;
}

// An unknown extension: the output is named once, the word "error" said once.
TEST(CliManners, ErrorsDoNotRepeatThemselves) {
    auto g = write_graph("jpg.yaml", std::string(kNoiseGraph) + "  - {node: n, file: d.jpg}\n");
    CliRun v = run("validate " + g.string());
    EXPECT_EQ(v.status, 1);
    EXPECT_NE(v.err.find("d.jpg"), std::string::npos) << v.err;
    EXPECT_EQ(v.err.find("output 'd.jpg'"), v.err.rfind("output 'd.jpg'")) << v.err;
    EXPECT_EQ(v.err.find("error"), v.err.rfind("error")) << v.err;
    EXPECT_EQ(v.err.rfind(g.string() + ":7:", 0), 0u) << v.err; // compiler form: FILE:LINE:COL: error: ...
}

namespace {
struct MeasuredRun {
    int status = -1;
    std::string err;
    long peak_rss_kb = 0; // the child's maximum resident set size (getrusage via wait4)
};
// Under AddressSanitizer the kernel-measured RSS also holds ASan's shadow memory (one
// byte for every 8 of memory the program touches) and its quarantine of freed blocks
// (256 MB by default). The measured runs turn the quarantine off, and the RSS bounds
// allow the shadow's eighth on top of what they allow the program itself.
#if defined(ATLAS_SANITIZED)
constexpr long kShadowNumerator = 9;
#else
constexpr long kShadowNumerator = 8;
#endif
long with_asan_shadow(long kb) { return kb * kShadowNumerator / 8; }

// The environment for a measured child: this one, with ASan's quarantine off.
std::vector<std::string> measured_environment() {
    std::vector<std::string> env;
    std::string asan = "quarantine_size_mb=0";
    for (char** e = environ; *e; ++e) {
        const std::string kv = *e;
        if (kv.rfind("ASAN_OPTIONS=", 0) == 0) asan = kv.substr(13) + ":" + asan;
        else env.push_back(kv);
    }
    env.push_back("ASAN_OPTIONS=" + asan);
    return env;
}

// Runs atlas (no shell, so the rusage is atlas's own) with stdout discarded.
MeasuredRun run_measured(const std::vector<std::string>& args) {
    const fs::path dir = atlas::test::process_dir("atlas_cli_measured");
    const std::string err = (dir / "err").string();
    const std::string prog = atlas::test::atlas_program();
    const std::vector<std::string> env_strings = measured_environment();
    std::vector<char*> argv{const_cast<char*>(prog.c_str())}, envp;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    for (const auto& e : env_strings) envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);
    std::fflush(nullptr); // the child must not write the parent's buffered output again
    const pid_t pid = fork();
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout) || !freopen(err.c_str(), "w", stderr)) _exit(126);
        execve(prog.c_str(), argv.data(), envp.data());
        _exit(127);
    }
    int st = 0;
    struct rusage ru{};
    wait4(pid, &st, 0, &ru);
    MeasuredRun r;
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.err = atlas::read_file_bytes(err);
    r.peak_rss_kb = ru.ru_maxrss;
    return r;
}
} // namespace

// Hostile mesh files never reach CGAL's PLY/STL readers unchecked (a property
// outside any element crashed it, so did a coordinate typed uchar; a huge element
// count or list length reserved memory for it).
TEST(CliHostile, MalformedPlyAndStlAreRefusedByName) {
    const fs::path d = fresh_dir("hostileply");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"noelem.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n"},
        {"huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 1\nproperty list uchar int vertex_indices\nend_header\n0123456789"},
        {"noface.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"},
        {"unended.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"},
        // A byte-typed coordinate reached a null pointer inside CGAL (sanitized fuzz run).
        {"ucharx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty uchar x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        // A list length in the body sized CGAL's buffer before it read the items (2^31 - 1
        // items asked for 7 GB; found by the sanitized fuzz run): binary and ascii.
        {"longlist.ply", std::string("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                     "element face 1\nproperty list int int vertex_indices\nend_header\n") +
                             std::string(36, '\0') + std::string("\xff\xff\xff\x7f", 4) + std::string(12, '\0')},
        {"longlist_ascii.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3000000000 0 1 2\n"},
        // ... and so did one behind a second, well-typed vertex element (the check saw only the last).
        {"twovertex.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty uchar x\nproperty float y\nproperty float z\n"
                          "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        // A body cut inside a list's length: CGAL sized the list from the bytes it half-read
        // (2.9 GB for this 220-byte file; sanitized fuzz run).
        {"cutlength.ply", std::string("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                      "element face 4\nproperty list int32 int vertex_indices\nend_header\n") +
                              std::string(48, '\0') + std::string("men", 3)},
        // A float-typed list length of -1e30: the message's integer of it was undefined
        // (sanitized fuzz smoke run in CI).
        {"negativelist.ply", std::string("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                         "element face 1\nproperty list float int vertex_indices\nend_header\n") +
                                 std::string(48, '\0') + std::string("\xca\xf2\x49\xf1", 4) + std::string(12, '\0')},
        {"huge.stl", std::string(80, 'x') + std::string("\xff\xff\xff\x7f", 4) + std::string(50, '\0')},
    };
    for (const auto& [name, bytes] : cases) {
        std::ofstream(d / name, std::ios::binary) << bytes;
        auto g = write_graph("mesh.yaml", "atlas: 1\nnodes:\n  m:\n    type: volume/read_mesh\n    params: {file: " + (d / name).string() +
                                              "}\n  s:\n    type: volume/mesh_to_sdf\n    inputs: {mesh: m}\noutputs:\n  - {node: s, port: sdf, file: s.exr}\n");
        const MeasuredRun r = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", (d / "out").string()});
        EXPECT_EQ(r.status, 1) << name << "\n" << r.err; // not a signal
        EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("node 'm'"), std::string::npos) << r.err;
        EXPECT_LT(r.peak_rss_kb, 1 << 20) << name; // under 1 GiB: nothing was reserved for the claimed counts
        // The cut length is refused by our check, not by CGAL after it sized the list from
        // whatever its half-read bytes said (not always over 1 GiB: that depends on memory).
        if (name == "cutlength.ply") {
            EXPECT_NE(r.err.find("the file ends in element 'face' entry 0"), std::string::npos) << r.err;
        }
        if (name == "negativelist.ply") {
            EXPECT_NE(r.err.find("element 'face' entry 0 has a list of a negative number of items"), std::string::npos) << r.err;
        }
    }
}

// A VDB cut short fails at once on its header (OpenVDB took 43 s and 5 GB,
// later 12 GB, to give up on one cut to 173 bytes); so does any shorter cut.
TEST(CliHostile, TruncatedVdbFailsFast) {
    const fs::path d = fresh_dir("truncvdb");
    auto g = write_graph("vdbsrc.yaml", std::string(kNoiseGraph) + "  - {node: n, file: n.vdb}\n");
    ASSERT_EQ(run("cook " + g.string() + " --no-cache --quiet --out " + d.string()).status, 0);
    const std::string full = atlas::read_file_bytes(d / "n.vdb");
    for (size_t cut : {size_t(173), size_t(60), size_t(124), full.size() / 2, full.size() - 1}) {
        std::ofstream(d / "t.vdb", std::ios::binary) << full.substr(0, cut);
        auto r = write_graph("vdbread.yaml", "atlas: 1\nnodes:\n  i:\n    type: import/vdb\n    params: {file: " + (d / "t.vdb").string() +
                                                 "}\noutputs:\n  - {node: i, file: o.exr}\n");
        const MeasuredRun m = run_measured({"cook", r.string(), "--no-cache", "--quiet", "--out", (d / "out").string()});
        EXPECT_EQ(m.status, 1) << cut << "\n" << m.err;
        EXPECT_NE(m.err.find("t.vdb"), std::string::npos) << m.err;
        EXPECT_LT(m.peak_rss_kb, 1 << 20) << cut;
    }
}

// --memory-budget holds the live total (issue 17 item 6): values held, the
// in-memory cache and new fields together. Five 8 MB fields, each under the
// budget, exceed 32 MiB together: the cook either stays under the budget (peak
// RSS over the same program's baseline, measured by the kernel) or refuses
// cleanly, naming the node.
TEST(CliBudget, LiveTotalStaysUnderTheBudgetOrIsRefusedByName) {
    const fs::path d = fresh_dir("budget");
    auto g = write_graph("budget.yaml",
                         "atlas: 1\nnodes:\n"
                         "  a:\n    type: noise/value\n    params: {resolution: [128, 128, 128], seed: 1}\n"
                         "  b:\n    type: noise/value\n    params: {resolution: [128, 128, 128], seed: 2}\n"
                         "  c:\n    type: math/binary\n    inputs: {a: a, b: b}\n"
                         "  d:\n    type: math/binary\n    params: {op: mul}\n    inputs: {a: c, b: b}\n"
                         "  e:\n    type: math/binary\n    params: {op: sub}\n    inputs: {a: d, b: a}\n"
                         "outputs:\n  - {node: e, file: e.exr}\n");
    // The program's own footprint: the same graph loaded, nothing cooked.
    const MeasuredRun base = run_measured({"validate", g.string()});
    ASSERT_EQ(base.status, 0) << base.err;
    const long budget_kb = 32 * 1024;
    // Without a budget the cook holds all five fields (the reference the budget must beat).
    const MeasuredRun free_run = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", (d / "free").string(), "--jobs", "1"});
    ASSERT_EQ(free_run.status, 0) << free_run.err;
    EXPECT_GT(free_run.peak_rss_kb - base.peak_rss_kb, with_asan_shadow(budget_kb)) << "the graph must need more than the budget to test it";
    for (const char* jobs : {"1", "2"}) {
        // A fresh --out per run: an unchanged output already on disk is not cooked again (item 1).
        const fs::path out = d / (std::string("out") + jobs);
        const MeasuredRun r = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", out.string(), "--memory-budget", "32M", "--jobs", jobs});
        if (r.status == 0) {
            // What the budget does not see: the EXR writer's strip buffers
            // (~4 MiB of rows; e.exr's size is a generous allowance for them)
            // and allocator slack, small next to the budget.
            const long file_kb = long(fs::file_size(out / "e.exr") / 1024);
            EXPECT_LE(r.peak_rss_kb - base.peak_rss_kb, with_asan_shadow(budget_kb + file_kb + budget_kb / 8))
                << "peak " << r.peak_rss_kb << " KiB, baseline " << base.peak_rss_kb << " KiB, output " << file_kb << " KiB, jobs " << jobs;
            EXPECT_EQ(atlas::read_file_bytes(out / "e.exr"), atlas::read_file_bytes(d / "free" / "e.exr"));
        } else {
            EXPECT_EQ(r.status, 1) << r.err;
            EXPECT_NE(r.err.find("memory budget of 32.0 MiB"), std::string::npos) << r.err;
            EXPECT_NE(r.err.find("node '"), std::string::npos) << r.err;
        }
    }
    // Under a budget too small for one field it is always a clean refusal.
    const MeasuredRun tiny = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", (d / "tiny").string(), "--memory-budget", "4M"});
    EXPECT_EQ(tiny.status, 1);
    EXPECT_NE(tiny.err.find("node 'a'"), std::string::npos) << tiny.err;
}

// A running node's scratch counts too (issue 17 item 6): volume/sdf works on
// more than one field besides its output. With room for the two values
// (density, distance) and one field more, the cook is refused naming 'sdf'
// (counting only finished values, it went through); with room for eight
// fields it cooks, the kernel-measured peak over the program's baseline stays
// under the budget plus a slack, and the bytes equal an unbudgeted cook.
TEST(CliBudget, RunningNodesScratchCountsAgainstTheBudget) {
    const fs::path d = fresh_dir("scratch");
    auto g = write_graph("scratch.yaml",
                         "atlas: 1\nnodes:\n"
                         "  puff:\n    type: volume/metaballs\n"
                         "    params: {kernel: metaball, weight: 2.5, resolution: [256, 256, 64], spheres: \"2000 2000 250 900\"}\n"
                         "  sdf:\n    type: volume/sdf\n    inputs: {in: puff}\n"
                         "outputs:\n  - {node: sdf, file: s.exr}\n");
    const long field_mib = 256 * 256 * 64 * 4 / (1 << 20); // one float channel
    const MeasuredRun base = run_measured({"validate", g.string()});
    ASSERT_EQ(base.status, 0) << base.err;
    const MeasuredRun free_run = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", (d / "free").string(), "--jobs", "1"});
    ASSERT_EQ(free_run.status, 0) << free_run.err;
    const std::string tight = std::to_string(3 * field_mib) + "MiB";
    const MeasuredRun refused = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", (d / "tight").string(), "--memory-budget", tight});
    EXPECT_EQ(refused.status, 1) << refused.err;
    EXPECT_NE(refused.err.find("node 'sdf'"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("over the memory budget"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(d / "tight" / "s.exr"));
    const long budget_kb = 8 * field_mib * 1024;
    for (const char* jobs : {"1", "2"}) {
        const fs::path out = d / (std::string("roomy") + jobs); // fresh: nothing to skip
        const MeasuredRun r = run_measured({"cook", g.string(), "--no-cache", "--quiet", "--out", out.string(), "--memory-budget",
                                            std::to_string(8 * field_mib) + "MiB", "--jobs", jobs});
        ASSERT_EQ(r.status, 0) << r.err;
        // Slack: what the budget does not see (the EXR writer's buffers, allocator slack).
        EXPECT_LE(r.peak_rss_kb - base.peak_rss_kb, with_asan_shadow(budget_kb + budget_kb / 8))
            << "peak " << r.peak_rss_kb << " KiB, baseline " << base.peak_rss_kb << " KiB, jobs " << jobs;
        EXPECT_EQ(atlas::read_file_bytes(out / "s.exr"), atlas::read_file_bytes(d / "free" / "s.exr"));
    }
}

// An input file larger than the memory budget is refused before a byte of it
// is read or hashed (a 20 GB sparse file used to be hashed whole first).
TEST(CliBudget, InputLargerThanTheBudgetIsRefusedBeforeReading) {
    const fs::path d = fresh_dir("biginput");
    { std::ofstream(d / "big.exr") << ""; }
    fs::resize_file(d / "big.exr", uint64_t(20) << 30); // sparse: no disk used
    auto g = write_graph("big.yaml", "atlas: 1\nnodes:\n  i:\n    type: import/exr\n    params: {file: " + (d / "big.exr").string() +
                                         "}\noutputs:\n  - {node: i, file: o.exr}\n");
    const auto t0 = std::chrono::steady_clock::now();
    CliRun r = run("cook " + g.string() + " --no-cache --quiet --out " + (d / "out").string() + " --memory-budget 1G");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("big.exr: the input file is 20.0 GiB, over the memory budget of 1.0 GiB"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("node 'i'"), std::string::npos) << r.err;
    (void)seconds; // (not asserted: speed is measured in bench/, never in tests)
    fs::remove(d / "big.exr");
}
