// Runs the atlas program the way a script does, for the CLI tests: stdout is
// collected through a pipe, stderr through a file, and the exit status kept.
#pragma once

#include "atlas/core/files.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace atlas::test {

struct CliRun {
    int status = -1; // exit status, -1 when the program did not exit normally
    std::string out, err;
};

// A scratch directory for this test process (ctest runs every test of a file as
// its own process, in parallel): TEMP/NAME_PID, created if missing.
inline std::filesystem::path process_dir(const std::string& name) {
    std::filesystem::path d = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
}

// The build's atlas program (ATLAS_BINARY_DIR is set for every test target).
inline std::string atlas_program() { return std::string(ATLAS_BINARY_DIR) + "/bin/atlas"; }

// Runs `command` (a shell command line whose stderr must go to `err_file`, e.g.
// "... 2>" + err_file) and returns what it printed.
inline CliRun run_shell(const std::string& command, const std::filesystem::path& err_file) {
    CliRun r;
    FILE* p = popen(command.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
    const int st = pclose(p);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.err = read_file_bytes(err_file);
    return r;
}

} // namespace atlas::test
