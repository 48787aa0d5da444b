// The checkout and the build folder, for the tests that read the repository's files or write
// beside the build. Every test sees this header through the tests' precompiled header
// (tests/CMakeLists.txt). The two folders are compiled into one small generated file per build
// folder (tests/test_dirs.cpp.in) instead of into every test: no test object then carries a path,
// so ccache gives a second clone or worktree the compiled tests of the first.
#pragma once

namespace driftless::test {
const char* source_dir();  // the checkout (the repository's root)
const char* binary_dir();  // the build folder
}  // namespace driftless::test

#define DRIFTLESS_SOURCE_DIR (::driftless::test::source_dir())
#define DRIFTLESS_BINARY_DIR (::driftless::test::binary_dir())
