// Where the C++ benchmarks find the checkout and the Python that runs their
// reference side (pyserial, python-can, canopen are installed in the
// project's venv, not in the system python3).
//
//   1. $MOTORBUS_BENCH_PYTHON (tools/bench.sh exports the venv python);
//   2. <checkout>/.venv/bin/python, the checkout found from the binary
//      (build/<dir>/bench_x) or the working directory, so a benchmark run by
//      hand from anywhere uses the venv `make build` created;
//   3. python3 on PATH (the reference then usually prints "unavailable").
//
// __FILE__ is not used to find the checkout: with CCACHE_BASEDIR (the
// Makefile sets it) it is relative to the build directory.
#pragma once
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace motorbus_bench {

// The checkout this benchmark belongs to (a directory holding bench/cpp and
// pyproject.toml), or an empty path.
inline std::filesystem::path repo_root() {
    namespace fs = std::filesystem;
    std::error_code ec;
    auto is_root = [&](const fs::path& p) {
        return fs::is_directory(p / "bench" / "cpp", ec) && fs::exists(p / "pyproject.toml", ec);
    };
    for (fs::path start : {fs::read_symlink("/proc/self/exe", ec).parent_path(), fs::current_path(ec)}) {
        for (fs::path p = start; !p.empty(); p = p.parent_path()) {
            if (is_root(p)) return p;
            if (p == p.root_path()) break;
        }
    }
    return {};
}

// The Python interpreter for reference measurements (see the file comment).
inline std::string python() {
    if (const char* env = std::getenv("MOTORBUS_BENCH_PYTHON"); env && *env) return env;
    const auto root = repo_root();
    if (!root.empty()) {
        const auto venv = root / ".venv" / "bin" / "python";
        if (::access(venv.c_str(), X_OK) == 0) return venv.string();
    }
    return "python3";
}

// A file of the checkout (e.g. "bench/sdo.py"), or `rel` itself when the
// checkout is not found (then relative to the working directory).
inline std::string repo_file(const std::string& rel) {
    const auto root = repo_root();
    return root.empty() ? rel : (root / rel).string();
}

}  // namespace motorbus_bench
