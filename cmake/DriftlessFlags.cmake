# driftless_flags: the warning and sanitizer settings every one of our targets links privately.
# (no global CMAKE_CXX_FLAGS: third-party code is compiled as its packagers intended)
add_library(driftless_flags INTERFACE)
add_library(driftless::flags ALIAS driftless_flags)
target_compile_options(driftless_flags INTERFACE -Wall -Wextra -Werror)
# Release builds our code at -O2 (after CMake's -O3, so it wins): GCC 12 at -O3 raises false
# -Wrestrict errors inside std::string (GCC bug 105329), and -O2 compiles faster
# The test programs (targets with the property DRIFTLESS_TEST_CODE: driftless_add_test and the
# tests' precompiled header, which must agree) at -O1: their code calls the libraries (still -O2)
# and checks the results, and -O1 compiles a test file in three quarters of -O2's CPU
# (estimator_tests_0.cpp 4.8 s against 6.8 s, diagnose_tests_0.cpp 8.6 s against 10.7 s).
# x86-64 arithmetic is the same IEEE double at either level (no FMA contraction without -march),
# so a test computes the same numbers.
target_compile_options(driftless_flags INTERFACE
  $<$<CONFIG:Release>:$<IF:$<BOOL:$<TARGET_PROPERTY:DRIFTLESS_TEST_CODE>>,-O1,-O2>>)
if(DRIFTLESS_SANITIZE)
  # -g1 (after the build type's -g, so it wins): line tables for the reports' stack traces at
  # 20 % less compile time. -Og: GCC's debugging level inlines Eigen's small functions, which -O0
  # calls one by one (the suite under the sanitizers spent ~20 min of CPU at -O0), and compiles as
  # fast as -O0 (measured: estimator/filter.cpp 23 s against 25 s, diagnose/channel_fit.cpp 30 s
  # against 27 s; -O1 took 30 s and 39 s)
  # -gz: the line tables compressed (zlib) in objects and programs (the sanitizer build took 4 GB);
  # the sanitizers' symbolizer reads them as before
  # -fno-sanitize=alignment,null: these two UBSan checks, on every pointer and reference use, were a
  # quarter of the sanitizer build's compile CPU (estimator/flip_update.cpp: 5.1 s with them, 3.9 s
  # without, 3.5 s with ASan alone; GCC 12, 2026-11-25). A null dereference still stops the run
  # (ASan reports the SEGV with its stack), and the misaligned reads that could come from bytes on
  # a wire or in a file are checked where those bytes are parsed: the fuzz harnesses (clang,
  # tests/fuzz) run with every UBSan check.
  target_compile_options(driftless_flags INTERFACE
    -fsanitize=address,undefined -fno-sanitize=alignment,null -fno-sanitize-recover=all -fno-omit-frame-pointer
    -g1 -Og -gz)
  target_link_options(driftless_flags INTERFACE -fsanitize=address,undefined -gz)
endif()

# driftless_pch_for_ccache(target): a target that builds or uses a precompiled header. clang writes
# the time stamps of the headers into the header it precompiles: every fresh clone's header then
# differs, and ccache, which hashes it, would compile every file that uses it again (ccache manual,
# "Precompiled headers"). GCC needs nothing (scripts/build.sh sets ccache's pch sloppiness).
function(driftless_pch_for_ccache target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    target_compile_options(${target} PRIVATE "SHELL:-Xclang -fno-pch-timestamp")
  endif()
endfunction()

# The libraries' precompiled header (driftless_libraries_pch): Eigen and the standard library,
# whose parse was about a third of a library file's compile CPU (~1.3 s of 3-4 s per file, in ~130
# files, GCC 12; the same in the sanitizer build). One header for every library, not one each: a
# GCC header of these is ~110 MB, and one per library made 2.3 GB in CI's two builds and pushed
# the tests' objects out of ccache's 1 GB (a warm CI of 2026-12-02 missed 89 of 406 compiles).
# Its flags are the libraries' own (driftless_flags; -fPIC in the shared sanitizer build), so GCC
# accepts it for each of them; what differs between libraries (their definitions, e.g. FMT_SHARED)
# does not appear in these headers.
add_library(driftless_libraries_pch OBJECT ${CMAKE_CURRENT_LIST_DIR}/pch_anchor.cpp)
target_link_libraries(driftless_libraries_pch PRIVATE Eigen3::Eigen driftless_flags)
set_target_properties(driftless_libraries_pch PROPERTIES POSITION_INDEPENDENT_CODE "${BUILD_SHARED_LIBS}")
target_precompile_headers(driftless_libraries_pch PRIVATE
  <Eigen/Core> <Eigen/Geometry>
  <algorithm> <array> <cmath> <cstdint> <limits> <memory> <sstream> <stdexcept> <string> <vector>)
driftless_pch_for_ccache(driftless_libraries_pch)
# driftless_library_pch(target [NOT_PCH file ...]): the library compiles with that header (ccache
# caches its files: scripts/build.sh sets its pch sloppiness). The NOT_PCH files compile without
# it: with the header precompiled, GCC 12 reports a false -Warray-bounds in them, inside
# std::string's inlined copy of a literal (GCC bugs 105329, 105651), not in our code.
function(driftless_library_pch target)
  cmake_parse_arguments(ARG "" "" "NOT_PCH" ${ARGN})
  target_precompile_headers(${target} REUSE_FROM driftless_libraries_pch)
  driftless_pch_for_ccache(${target})
  if(ARG_NOT_PCH)
    set_source_files_properties(${ARG_NOT_PCH} PROPERTIES SKIP_PRECOMPILE_HEADERS ON)
  endif()
endfunction()

# the repository root is the include root, so an include names its folder:
#   #include "estimator/log.hpp"   (and estimator/ never includes twin/, hil_bridge/ or renders/)
set(DRIFTLESS_SOURCE_ROOT ${PROJECT_SOURCE_DIR})

# the tests' temporary folder (TMPDIR), one per build tree
set(DRIFTLESS_TEST_TMPDIR ${PROJECT_BINARY_DIR}/tmp)
file(MAKE_DIRECTORY ${DRIFTLESS_TEST_TMPDIR})
# every test runs through this script: TMPDIR becomes a folder of the test's own under the one
# above, removed when the test passes, so the files of passed tests do not pile up on the disk
# (tests/run_in_scratch.sh)
set(DRIFTLESS_TEST_RUNNER ${PROJECT_SOURCE_DIR}/tests/run_in_scratch.sh)

# driftless_add_test(name SOURCES ... LIBS ...): one GoogleTest binary registered with CTest.
function(driftless_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  # the checkout and build folders come from driftless_test_dirs at run time, not from compile
  # definitions: test objects hold no path, and ccache shares them between clones (tests/test_dirs.hpp)
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} driftless_test_dirs GTest::gtest GTest::gtest_main
                        driftless::flags)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests
                        DRIFTLESS_TEST_CODE ON)
  # gtest_discover_tests puts the 'emulator' in front of each test's command: the scratch runner
  set_target_properties(${name} PROPERTIES CROSSCOMPILING_EMULATOR ${DRIFTLESS_TEST_RUNNER})
  # GoogleTest, Eigen and the standard library parsed once for every test (tests/CMakeLists.txt)
  target_precompile_headers(${name} REUSE_FROM driftless_test_pch)
  driftless_pch_for_ccache(${name})
  # with the standard library from a precompiled header, GCC 12 at -O2 inlines std::string's
  # operator+ chains further and reports false -Warray-bounds, -Wrestrict and -Wstringop-overflow
  # on them (GCC bugs 105329, 105651); test code only, the product keeps these warnings as errors
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${name} PRIVATE -Wno-array-bounds -Wno-restrict -Wno-stringop-overflow)
  endif()
  # TMPDIR inside the build tree: two build trees (a second clone, the sanitizer build) running
  # their suites at once never share a temporary file
  # COST: the statistical claims (label 'slow', 2-30 s each) start before everything else, as ctest
  # -j does with timings it measured itself (a fresh clone has none); the cli tests come next (cost
  # 10, tests/cli/CMakeLists.txt) and the many short unit tests fill the end of the pass
  set(cost 0)
  if("${ARG_LABELS}" STREQUAL "slow")
    set(cost 20)
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES LABELS "${ARG_LABELS}" ENVIRONMENT "TMPDIR=${DRIFTLESS_TEST_TMPDIR}" COST ${cost}
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
endfunction()

# the unity batches' size (driftless_add_tests_in_folder, below)
set(DRIFTLESS_TEST_UNITY_BATCH 8 CACHE STRING "test files per translation unit (unity build); 1: one per file")
# driftless_unity_batches(OUT prefix size file...): the files as unity batches of size files each
# (the tests: DRIFTLESS_TEST_UNITY_BATCH; the driftless program: DRIFTLESS_CLI_UNITY_BATCH), written
# into this build folder. Each batch includes its files by their
# path from the repository root (on every test's include path), not by the absolute path CMake's own
# UNITY_BUILD writes (CMake < 3.32): a clone at another path then compiles the same text, and ccache
# finds its objects (CI's clean clone with a warm cache). A batch file is rewritten only when its
# list changes, so a re-run of CMake recompiles nothing.
function(driftless_unity_batches out prefix size)
  set(sources "")
  set(text "")
  set(count 0)
  set(index 0)
  foreach(f ${ARGN} "")
    if(f)
      file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${f})
      string(APPEND text "#include \"${rel}\"\n")
      math(EXPR count "${count} + 1")
    endif()
    if(count GREATER 0 AND (count EQUAL size OR NOT f))
      set(batch ${CMAKE_CURRENT_BINARY_DIR}/unity/${prefix}_${index}.cpp)
      file(CONFIGURE OUTPUT ${batch} CONTENT "// generated by driftless_unity_batches: do not edit\n${text}")
      list(APPEND sources ${batch})
      math(EXPR index "${index} + 1")
      set(text "")
      set(count 0)
    endif()
  endforeach()
  set(${out} ${sources} PARENT_SCOPE)
endfunction()

# driftless_add_tests_in_folder(LIBS ... [ALONE stem ...]): the test_*.cpp files here and in the
# subfolders make one GoogleTest program, <folder>_tests; the slow_test_*.cpp files another,
# <folder>_slow_tests (label 'slow'). A file named in ALONE (its stem) is a program of its own,
# <folder>_<stem>, for flags the others do not share. The tests' names (Suite.Name) and labels are
# the same as with one program per file; CTest runs each test as before.
# One program per folder instead of one per file: ~100 links and ~100 test listings (each run at
# build time) become ~20, and the files of a program compile in unity batches
# (DRIFTLESS_TEST_UNITY_BATCH files per translation unit): GoogleTest's and Eigen's templates are
# instantiated once a batch instead of once a file. A file whose names clash with another's in a
# batch is named in the folder's NOT_UNITY list: it compiles on its own, in the same program.
function(driftless_add_tests_in_folder)
  cmake_parse_arguments(ARG "" "" "LIBS;ALONE;NOT_UNITY" ${ARGN})
  # subfolders mirror the source's (tests/twin/sensor/ for twin/sensor/); the label and the
  # target prefix stay the top folder's
  file(GLOB_RECURSE files CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/test_*.cpp
       ${CMAKE_CURRENT_SOURCE_DIR}/slow_test_*.cpp)
  list(SORT files)
  get_filename_component(folder ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  foreach(list tests_batched tests_alone slow_tests_batched slow_tests_alone)
    set(${list} "")
  endforeach()
  foreach(f ${files})
    get_filename_component(stem ${f} NAME_WE)
    # one label per test: a list would be split into separate PROPERTIES arguments by
    # gtest_discover_tests and 'slow' would be lost (the sanitizer pass runs ctest -LE slow)
    set(labels ${folder})
    if(stem MATCHES "^slow_")
      if(NOT DRIFTLESS_BUILD_SLOW_TESTS)
        continue()
      endif()
      set(labels slow)
    endif()
    if(stem IN_LIST ARG_ALONE)
      driftless_add_test(${folder}_${stem} SOURCES ${f} LIBS ${ARG_LIBS} LABELS "${labels}")
      continue()
    endif()
    set(kind tests)
    if(stem MATCHES "^slow_")
      set(kind slow_tests)
    endif()
    # a file in NOT_UNITY compiles on its own; the others go into the batches
    set(part batched)
    if(stem IN_LIST ARG_NOT_UNITY OR DRIFTLESS_TEST_UNITY_BATCH LESS_EQUAL 1)
      set(part alone)
    endif()
    list(APPEND ${kind}_${part} ${f})
  endforeach()
  foreach(kind tests slow_tests)
    set(labels ${folder})
    if(kind STREQUAL "slow_tests")
      set(labels slow)
    endif()
    driftless_unity_batches(batches ${folder}_${kind} ${DRIFTLESS_TEST_UNITY_BATCH} ${${kind}_batched})
    set(sources ${batches} ${${kind}_alone})
    if(sources)
      driftless_add_test(${folder}_${kind} SOURCES ${sources} LIBS ${ARG_LIBS} LABELS "${labels}")
    endif()
  endforeach()
endfunction()

# driftless_add_benchmarks_in_folder(LIBS ...): every bench_*.cpp here is one benchmark program.
function(driftless_add_benchmarks_in_folder)
  cmake_parse_arguments(ARG "" "" "LIBS" ${ARGN})
  file(GLOB files CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/bench_*.cpp)
  foreach(f ${files})
    get_filename_component(stem ${f} NAME_WE)
    add_executable(${stem} ${f})
    target_link_libraries(${stem} PRIVATE ${ARG_LIBS} benchmark::benchmark driftless::flags)
    target_compile_definitions(${stem} PRIVATE DRIFTLESS_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    set_target_properties(${stem} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bench)
  endforeach()
endfunction()
