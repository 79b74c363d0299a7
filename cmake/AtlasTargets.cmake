# Helpers shared by every Atlas target: warnings (errors in CI), sanitizers.
# Two compilers build Atlas: GCC (the Release build, what ships) and clang (the
# sanitizer build of scripts/test.sh: half GCC's compile time with ASan + UBSan,
# docs/DECISIONS.md), so the GCC-only warning names are GCC's alone.

add_library(atlas_warnings INTERFACE)
target_compile_options(atlas_warnings INTERFACE -Wall -Wextra -Wpedantic
  -Wnon-virtual-dtor -Wno-missing-field-initializers
  # GCC 12 reports false -Wrestrict positives inside std::string (GCC bug 105329).
  $<$<CXX_COMPILER_ID:GNU>:-Wshadow=local -Wno-restrict>
  # clang has no -Wshadow=local; its -Wshadow (locals and fields) is the stricter superset,
  # so CI's clang build catches what GCC's Release build would.
  $<$<CXX_COMPILER_ID:Clang>:-Wshadow -Wshadow-uncaptured-local>)
if(ATLAS_WERROR)
  target_compile_options(atlas_warnings INTERFACE -Werror)
endif()
if(ATLAS_SANITIZE)
  # ASan's instrumentation makes GCC 12 report false -Wmaybe-uninitialized
  # positives inside libstdc++ (std::function, std::regex); keep them as warnings.
  target_compile_options(atlas_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
    -fno-sanitize-recover=undefined $<$<CXX_COMPILER_ID:GNU>:-Wno-error=maybe-uninitialized>
    # Third-party headers' known reports, one check each (tests/sanitizer/ubsan_ignore.txt);
    # for Atlas's own compiles only (an installed package must not name the source tree).
    $<BUILD_INTERFACE:$<$<CXX_COMPILER_ID:Clang>:-fsanitize-ignorelist=${PROJECT_SOURCE_DIR}/tests/sanitizer/ubsan_ignore.txt>>)
  target_link_options(atlas_warnings INTERFACE -fsanitize=address,undefined)
  # ATLAS_ASAN_RUNTIME: the ASan runtime as a shared library. clang links it
  # statically by default, which clashes with the copy a test preloads into a host
  # program (Python, Blender) that then runs the atlas CLI: with -shared-libsan
  # every program and library of the build uses the one shared runtime.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    set(_asan_rt_name libclang_rt.asan-x86_64.so)
  else()
    set(_asan_rt_name libasan.so)
  endif()
  execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=${_asan_rt_name}
                  OUTPUT_VARIABLE ATLAS_ASAN_RUNTIME OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    get_filename_component(_asan_rt_dir "${ATLAS_ASAN_RUNTIME}" DIRECTORY)
    target_link_options(atlas_warnings INTERFACE -shared-libsan "LINKER:-rpath,${_asan_rt_dir}")
  endif()
endif()

# atlas_module(NAME DEPS...): a static library libatlas/src/NAME/*.cpp with the
# public headers in libatlas/include/atlas/NAME. Modules are separate targets so
# that the dependency graph between them stays visible and explicit.
function(atlas_module name)
  file(GLOB _srcs CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/src/${name}/*.cpp")
  if(NOT _srcs)
    # A module with headers only (or not written yet) is an interface target.
    add_library(atlas_${name} INTERFACE)
    add_library(atlas::${name} ALIAS atlas_${name})
    target_include_directories(atlas_${name} INTERFACE "$<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>"
      "$<INSTALL_INTERFACE:include>")
    target_link_libraries(atlas_${name} INTERFACE ${ARGN})
    set_property(GLOBAL APPEND PROPERTY ATLAS_MODULE_TARGETS atlas_${name})
    return()
  endif()
  add_library(atlas_${name} STATIC ${_srcs})
  add_library(atlas::${name} ALIAS atlas_${name})
  # Build tree: the source headers; installed tree: <prefix>/include (cmake/AtlasInstall.cmake).
  target_include_directories(atlas_${name} PUBLIC "$<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>"
    "$<INSTALL_INTERFACE:include>")
  target_link_libraries(atlas_${name} PUBLIC ${ARGN} PRIVATE atlas_warnings)
  # PIC: the same objects also make the shared libatlas and the Python module.
  set_target_properties(atlas_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  set_property(GLOBAL APPEND PROPERTY ATLAS_MODULE_TARGETS atlas_${name})
endfunction()

# atlas_test(NAME SOURCES... LIBS ...): one GoogleTest binary registered with ctest.
function(atlas_test name)
  cmake_parse_arguments(T "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_LIBS} atlas_gtest_main atlas_warnings)
  target_compile_definitions(${name} PRIVATE
    ATLAS_SOURCE_DIR="${PROJECT_SOURCE_DIR}" ATLAS_BINARY_DIR="${PROJECT_BINARY_DIR}"
    # Tests that size their work or measure RSS ask this, not a compiler's own macro
    # (GCC defines __SANITIZE_ADDRESS__, clang 14 does not).
    $<$<BOOL:${ATLAS_SANITIZE}>:ATLAS_SANITIZED=1>)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS unit)
  # Every suite is listed, so scripts/test.sh can build and run them all under sanitizers
  # (target unit_suites, tests/CMakeLists.txt).
  set_property(GLOBAL APPEND PROPERTY ATLAS_TEST_SUITES ${name})
endfunction()

# atlas_benchmark(NAME SOURCES... LIBS ...): a Google Benchmark program. Each
# is also registered with ctest as a short smoke run (label "bench"), so CI
# proves it still runs without paying for a full measurement.
function(atlas_benchmark name)
  cmake_parse_arguments(B "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${B_SOURCES})
  target_link_libraries(${name} PRIVATE ${B_LIBS} benchmark::benchmark atlas_warnings)
  target_compile_definitions(${name} PRIVATE ATLAS_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_test(NAME ${name}_smoke COMMAND ${name} --benchmark_min_time=0.01 --benchmark_filter=Smoke)
  set_tests_properties(${name}_smoke PROPERTIES LABELS bench)
endfunction()
