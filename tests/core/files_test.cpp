#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "../../libatlas/src/core/file_limits.h"

#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include <sys/stat.h>

using namespace atlas;

namespace {
fs::path temp_dir(const std::string& name) {
    fs::path d = fs::temp_directory_path() / ("atlas_files_" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}
void write(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }
} // namespace

TEST(StagedOutputs, CommitMovesEverythingIntoPlace) {
    fs::path d = temp_dir("commit");
    {
        StagedOutputs s(d);
        write(s.stage("a.txt"), "A");
        write(s.stage("sub/b.txt"), "B");
        EXPECT_FALSE(fs::exists(d / "a.txt"));
        auto files = s.commit();
        EXPECT_EQ(files.size(), 2u);
    }
    EXPECT_EQ(read_file_bytes(d / "a.txt"), "A");
    EXPECT_EQ(read_file_bytes(d / "sub" / "b.txt"), "B");
    for (const auto& e : fs::directory_iterator(d)) EXPECT_EQ(e.path().filename().string().find(".atlas-staging"), std::string::npos);
    fs::remove_all(d);
}

TEST(StagedOutputs, WithoutCommitNothingChanges) {
    fs::path d = temp_dir("abort");
    write(d / "a.txt", "old");
    {
        StagedOutputs s(d);
        write(s.stage("a.txt"), "new");
        write(s.stage("b.txt"), "new");
    }
    EXPECT_EQ(read_file_bytes(d / "a.txt"), "old");
    EXPECT_FALSE(fs::exists(d / "b.txt"));
    EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);
    fs::remove_all(d);
}

TEST(WriteFileAtomic, ThrowingWriterLeavesTheOldFile) {
    fs::path d = temp_dir("atomic");
    write(d / "x", "old");
    EXPECT_THROW(write_file_atomic(d / "x", [](const fs::path& tmp) {
        write(tmp, "half");
        throw Error("disk full");
    }), Error);
    EXPECT_EQ(read_file_bytes(d / "x"), "old");
    write_file_atomic(d / "x", [](const fs::path& tmp) { write(tmp, "new"); });
    EXPECT_EQ(read_file_bytes(d / "x"), "new");
    fs::remove_all(d);
}

TEST(ResolveOutputPath, RefusesEscapes) {
    fs::path d = temp_dir("resolve");
    EXPECT_EQ(resolve_output_path(d, "a/b.exr", false), (d / "a/b.exr").lexically_normal());
    EXPECT_EQ(resolve_output_path(d, "a/../b.exr", false), (d / "b.exr").lexically_normal());
    EXPECT_THROW(resolve_output_path(d, "../b.exr", false), Error);
    EXPECT_THROW(resolve_output_path(d, "/etc/passwd", false), Error);
    EXPECT_THROW(resolve_output_path(d, "", false), Error);
    EXPECT_NO_THROW(resolve_output_path(d, "../b.exr", true));
    fs::create_directories(d / "out");
    fs::create_directory_symlink(fs::temp_directory_path(), d / "out" / "tmp");
    EXPECT_THROW(resolve_output_path(d / "out", "tmp/x.exr", false), Error);
    fs::remove_all(d);
}

TEST(ReadFile, NamesTheMissingFile) {
    try {
        read_file_bytes("/nonexistent/dir/f.yaml");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/f.yaml"), std::string::npos);
    }
}

// Regular files are read with one sized read, binary-exact (NUL and high bytes);
// pipes (no size) fall back to streaming.
TEST(ReadFile, ReadsBinaryFilesAndPipes) {
    const fs::path d = temp_dir("read");
    std::string bytes(100000, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char((i * 131) & 0xff);
    std::ofstream(d / "bin", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    EXPECT_EQ(read_file_bytes(d / "bin"), bytes);
    write(d / "empty", "");
    EXPECT_EQ(read_file_bytes(d / "empty"), "");

    const fs::path fifo = d / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::thread writer([&] { std::ofstream(fifo, std::ios::binary) << "through a pipe"; });
    const std::string got = read_file_bytes(fifo);
    writer.join();
    EXPECT_EQ(got, "through a pipe");
}

// Hashing a large input stops at a cancellation (issue 17 item 8): the hasher
// polls between chunks, so a cancel raised on its second poll ends the hash
// there (CancelledError) instead of reading the 8 GiB sparse file to its end,
// and no poll follows. Without a cancel the same poll counts the whole file.
TEST(HashFile, CancellingWhileHashingALargeInputStopsAtTheNextPoll) {
    const fs::path d = temp_dir("hash_cancel");
    const fs::path big = d / "big.bin";
    { std::ofstream(big) << ""; }
    fs::resize_file(big, uint64_t(8) << 30); // sparse: no disk used
    int polls = 0;
    {
        const detail::FileReadLimits limits(~uint64_t(0), [&] { return ++polls >= 2; });
        Hasher h;
        EXPECT_THROW(hash_file(h, big), CancelledError);
    }
    EXPECT_EQ(polls, 2);
    // The reference: a small file, never cancelled, is read to its end and polled at least once.
    const fs::path small = d / "small.bin";
    write(small, std::string(1000, 'x'));
    int small_polls = 0;
    {
        const detail::FileReadLimits limits(~uint64_t(0), [&] { return ++small_polls < 0; });
        Hasher h;
        hash_file(h, small);
    }
    EXPECT_GE(small_polls, 1);
    fs::remove_all(d);
}
