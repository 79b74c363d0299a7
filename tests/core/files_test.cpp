#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/core/file_limits.h"

#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include <chrono>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

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
// Special files are refused by type before the open (issue 48): a FIFO's open
// would block until a writer came, a directory claimed an absurd size.
TEST(ReadFile, ReadsBinaryFilesAndRefusesPipesAndDirectories) {
    const fs::path d = temp_dir("read");
    std::string bytes(100000, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char((i * 131) & 0xff);
    std::ofstream(d / "bin", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    EXPECT_EQ(read_file_bytes(d / "bin"), bytes);
    write(d / "empty", "");
    EXPECT_EQ(read_file_bytes(d / "empty"), "");

    const fs::path fifo = d / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    for (const fs::path& p : {fifo, d}) {
        try {
            read_file_bytes(p); // no writer: an open would block for ever
            FAIL() << p;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
        }
    }
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

// ----------------------------------------------------------- hostile destinations
// Atlas never replaces or writes through what it did not create (issue 48).

TEST(WriteFileAtomic, RefusesALinkAndLeavesItAndItsTarget) {
    fs::path d = temp_dir("link_dest");
    write(d / "target", "precious");
    fs::create_symlink(d / "target", d / "report.json");
    EXPECT_THROW(write_file_atomic(d / "report.json", [](const fs::path& tmp) { write(tmp, "{}"); }), Error);
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d / "report.json")));
    EXPECT_EQ(read_file_bytes(d / "target"), "precious");
    fs::remove_all(d);
}

TEST(WriteFileAtomic, RefusesAFifoADirectoryAndADevice) {
    fs::path d = temp_dir("special_dest");
    ASSERT_EQ(::mkfifo((d / "pipe").c_str(), 0600), 0);
    fs::create_directories(d / "dir");
    for (const fs::path& p : {d / "pipe", d / "dir"}) {
        try {
            write_file_atomic(p, [](const fs::path& tmp) { write(tmp, "{}"); });
            FAIL() << p;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(fs::is_fifo(d / "pipe"));
    EXPECT_TRUE(fs::is_directory(d / "dir"));
    // A device is refused by its type before anything is staged beside it
    // (as root, a rename would have replaced /dev/null with a JSON file).
    EXPECT_THROW(check_destination("/dev/null"), Error);
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
    fs::remove_all(d);
}

TEST(WriteFileAtomic, RefusesAProtectedFileUnderAnyName) {
    fs::path d = temp_dir("protected_dest");
    write(d / "graph.yaml", "atlas: 1");
    fs::create_hard_link(d / "graph.yaml", d / "alias.yaml");
    const std::vector<ProtectedFile> protect = {{d / "graph.yaml", "the graph file"}};
    for (const fs::path& p : {d / "graph.yaml", d / "alias.yaml", d / "sub" / ".." / "graph.yaml"}) {
        try {
            write_file_atomic(p, [](const fs::path& tmp) { write(tmp, "{}"); }, protect);
            FAIL() << p;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("would overwrite the graph file"), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(read_file_bytes(d / "graph.yaml"), "atlas: 1");
    fs::remove_all(d);
}

TEST(StagedOutputs, TwoNamesReachingOneFileThroughALinkedFolderAreRefused) {
    fs::path d = temp_dir("one_file_two_names");
    fs::create_directories(d / "real");
    fs::create_directory_symlink(d / "real", d / "alias");
    {
        StagedOutputs s(d);
        write(s.stage("real/x.exr"), "A");
        write(s.stage("alias/x.exr"), "B");
        try {
            s.commit();
            FAIL();
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("are one file"), std::string::npos) << e.what();
        }
    }
    EXPECT_FALSE(fs::exists(d / "real" / "x.exr"));
    fs::remove_all(d);
}

TEST(StagedOutputs, ALinkedFolderLeadingOutsideTheRootIsRefused) {
    fs::path d = temp_dir("link_outside");
    fs::create_directories(d / "out");
    fs::create_directories(d / "elsewhere");
    fs::create_directory_symlink(d / "elsewhere", d / "out" / "link");
    {
        StagedOutputs s(d / "out");
        write(s.stage("link/evil.exr"), "X");
        EXPECT_THROW(s.commit(), Error);
    }
    EXPECT_FALSE(fs::exists(d / "elsewhere" / "evil.exr"));
    fs::remove_all(d);
}

TEST(StagedOutputs, AFolderNamedLikeStagingThatAtlasDidNotMakeIsKept) {
    fs::path d = temp_dir("user_staging_name");
    const fs::path mine = d / ".atlas-staging-host-1-0123456789abcdef";
    fs::create_directories(mine);
    write(mine / "render.exr", "mine");
    fs::last_write_time(mine, fs::file_time_type::clock::now() - std::chrono::hours(48));
    EXPECT_EQ(remove_stale_staging(d), 0u);
    EXPECT_EQ(read_file_bytes(mine / "render.exr"), "mine");
    fs::remove_all(d);
}

TEST(StagedOutputs, RecordsAreCommittedLast) {
    fs::path d = temp_dir("records_last");
    StagedOutputs s(d);
    write(s.stage_last("a_fragment.json"), "record");
    write(s.stage("b.exr"), "B");
    write(s.stage("z/c.exr"), "C");
    const auto order = s.staged_files();
    ASSERT_EQ(order.size(), 3u);
    EXPECT_EQ(order.back(), fs::path("a_fragment.json"));
    const auto done = s.commit();
    EXPECT_EQ(done.back(), d / "a_fragment.json");
    fs::remove_all(d);
}

// A process killed during the moves leaves a mix of old and new files; the
// next run in the directory completes the commit from its journal.
TEST(StagedOutputs, ACommitKilledHalfwayIsCompletedByTheNextRun) {
    fs::path d = temp_dir("killed_commit");
    for (const char* n : {"a.exr", "b.exr", "c.exr"}) write(d / n, "old");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        StagedOutputs s(d);
        for (const char* n : {"a.exr", "b.exr", "c.exr"}) write(s.stage(n), "new");
        s.prepare();
        // The first move, as commit() makes it, then death (no destructor runs).
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(d))
            if (e.path().filename().string().rfind(".atlas-staging-", 0) == 0) fs::rename(e.path() / "a.exr", d / "a.exr", ec);
        ::_exit(ec ? 1 : 0);
    }
    int st = 0;
    ASSERT_EQ(::waitpid(child, &st, 0), child);
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    // The mix a killed commit leaves: a new, b and c old.
    EXPECT_EQ(read_file_bytes(d / "a.exr"), "new");
    EXPECT_EQ(read_file_bytes(d / "b.exr"), "old");
    remove_stale_staging(d);
    for (const char* n : {"a.exr", "b.exr", "c.exr"}) EXPECT_EQ(read_file_bytes(d / n), "new") << n;
    for (const auto& e : fs::directory_iterator(d)) EXPECT_EQ(e.path().filename().string().find(".atlas-staging"), std::string::npos) << e.path();
    fs::remove_all(d);
}

TEST(ResolveOutputPath, RefusesControlCharactersAndAtlasOwnNames) {
    fs::path d = temp_dir("resolve_names");
    EXPECT_THROW(resolve_output_path(d, std::string("o.exr\0.png", 10), false), Error);
    EXPECT_THROW(resolve_output_path(d, "a\nb.exr", false), Error);
    EXPECT_THROW(resolve_output_path(d, ".atlas-outputs.json", false), Error);
    EXPECT_THROW(resolve_output_path(d, ".atlas-staging-x/out.exr", false), Error);
    EXPECT_THROW(resolve_output_path(d, ".atlas-outputs.json", true), Error);
    EXPECT_NO_THROW(resolve_output_path(d, ".atlasrc/out.exr", false));
    fs::remove_all(d);
}
