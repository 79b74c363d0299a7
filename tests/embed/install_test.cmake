# Installs the build tree into a scratch prefix, then configures and builds
# examples/embed against that prefix alone (find_package(Atlas), not the build
# tree) and runs both hosts on the quickstart.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DLAUNCHER=ccache]
#         [-DHOST_C_COMPILER=... -DHOST_CXX_COMPILER=...] -P install_test.cmake
# WORK_DIR is fixed (inside the build tree) so that ccache sees the same paths each run.
foreach(v BUILD_DIR SOURCE_DIR WORK_DIR)
  if(NOT ${v})
    message(FATAL_ERROR "install_test: ${v} not given")
  endif()
endforeach()
set(prefix "${WORK_DIR}/prefix")
set(host "${WORK_DIR}/host")
file(REMOVE_RECURSE "${WORK_DIR}")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install_test: failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

run("${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" --component development)
foreach(f include/atlas/atlas.h include/atlas/graph/evaluator.h lib/cmake/Atlas/AtlasConfig.cmake
          lib/cmake/Atlas/AtlasConfigVersion.cmake lib/cmake/Atlas/AtlasTargets.cmake)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "install_test: ${prefix}/${f} was not installed")
  endif()
endforeach()

# Only the prefix: no path into the build or source tree may be needed.
set(launcher "")
if(LAUNCHER)
  set(launcher "-DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}" "-DCMAKE_C_COMPILER_LAUNCHER=${LAUNCHER}")
endif()
if(HOST_C_COMPILER AND HOST_CXX_COMPILER)
  list(APPEND launcher "-DCMAKE_C_COMPILER=${HOST_C_COMPILER}" "-DCMAKE_CXX_COMPILER=${HOST_CXX_COMPILER}")
endif()
run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}/examples/embed" -B "${host}" -G Ninja -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_PREFIX_PATH=${prefix}" ${launcher})
file(READ "${host}/CMakeCache.txt" cache)
string(FIND "${cache}" "Atlas_DIR:PATH=${prefix}/lib/cmake/Atlas" found)
if(found EQUAL -1)
  message(FATAL_ERROR "install_test: Atlas was not found in ${prefix}")
endif()
run("${CMAKE_COMMAND}" --build "${host}")
# The installed export must not point back at the build or source tree.
file(READ "${prefix}/lib/cmake/Atlas/AtlasTargets.cmake" targets)
file(GLOB target_files "${prefix}/lib/cmake/Atlas/AtlasTargets-*.cmake")
foreach(t IN LISTS target_files)
  file(READ "${t}" more)
  string(APPEND targets "${more}")
endforeach()
foreach(tree "${BUILD_DIR}" "${SOURCE_DIR}")
  string(FIND "${targets}" "${tree}/" leak)
  if(NOT leak EQUAL -1)
    message(FATAL_ERROR "install_test: the installed targets name ${tree}")
  endif()
endforeach()

run("${host}/atlas_embed_example" "${SOURCE_DIR}/examples/quickstart.yaml")
# Changing coverage.in_min re-cooks coverage and what depends on it, never 'base'.
if(NOT run_output MATCHES "re-cooked:( [a-z_]+)* coverage( [a-z_]+)*\nfrom cache: [a-z_]+( [a-z_]+)*\n" OR run_output MATCHES "re-cooked:[^\n]* base[ \n]")
  message(FATAL_ERROR "install_test: unexpected output of atlas_embed_example:\n${run_output}")
endif()
run("${host}/atlas_embed_c" "${SOURCE_DIR}/examples/quickstart.yaml" coverage)
if(NOT run_output MATCHES "coverage: 128x128x32, 1 channel\\(s\\), 'density' in \\[0, 1\\]")
  message(FATAL_ERROR "install_test: unexpected output of atlas_embed_c:\n${run_output}")
endif()
# A C-only host project: the same C program, with only C enabled by the host.
run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}/tests/embed/c_only_host" -B "${host}-c" -G Ninja -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_PREFIX_PATH=${prefix}" "-DATLAS_EXAMPLES_DIR=${SOURCE_DIR}/examples/embed" ${launcher})
run("${CMAKE_COMMAND}" --build "${host}-c")
run("${host}-c/atlas_c_only_host" "${SOURCE_DIR}/examples/quickstart.yaml" coverage)
if(NOT run_output MATCHES "coverage: 128x128x32, 1 channel\\(s\\), 'density' in \\[0, 1\\]")
  message(FATAL_ERROR "install_test: unexpected output of the C-only host:\n${run_output}")
endif()
message(STATUS "install_test: built and ran examples/embed and a C-only host against ${prefix}")
