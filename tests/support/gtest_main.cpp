// main() of every GoogleTest suite: each test process gets a private scratch
// directory as its TMPDIR (std::filesystem::temp_directory_path, tmpfile and the
// atlas CLI it runs all follow TMPDIR), removed when the process ends. Without
// it the suites left ~100 MB of scratch in /tmp per run. A failed run keeps its
// directory and names it, for the post-mortem; ATLAS_KEEP_TEST_TMP=1 keeps every one.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

int main(int argc, char** argv) {
    testing::InitGoogleTest(&argc, argv);
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path parent = fs::temp_directory_path(ec);
    std::string scratch = ((ec ? fs::path("/tmp") : parent) / "atlas-test-XXXXXX").string();
    const bool made = ::mkdtemp(scratch.data()) != nullptr;
    const char* outer = std::getenv("TMPDIR");
    const std::string outer_tmpdir = outer ? outer : "";
    if (made) ::setenv("TMPDIR", scratch.c_str(), 1);
    const int rc = RUN_ALL_TESTS();
    if (made) {
        const char* keep = std::getenv("ATLAS_KEEP_TEST_TMP");
        if (rc != 0 || (keep && std::string(keep) == "1"))
            std::fprintf(stderr, "test scratch kept: %s\n", scratch.c_str());
        else
            fs::remove_all(scratch, ec);
        // Exit-time code (static destructors) must not see a TMPDIR that is gone.
        if (outer) ::setenv("TMPDIR", outer_tmpdir.c_str(), 1);
        else ::unsetenv("TMPDIR");
    }
    return rc;
}
