# Every production graph and example must stay valid (`atlas validate`, cheap) and cook on a
# fresh clone (a scratch copy of graphs/ and examples/; tests/cli/cook_shipped_graph.sh).
file(GLOB ATLAS_GRAPH_FILES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/graphs/*.yaml" "${PROJECT_SOURCE_DIR}/examples/*.yaml")
foreach(graph IN LISTS ATLAS_GRAPH_FILES)
  get_filename_component(name "${graph}" NAME_WE)
  add_test(NAME validate_${name} COMMAND atlas validate "${graph}")
  set_tests_properties(validate_${name} PROPERTIES LABELS graph)
  file(RELATIVE_PATH rel "${PROJECT_SOURCE_DIR}" "${graph}")
  add_test(NAME cook_shipped_${name} COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/cook_shipped_graph.sh $<TARGET_FILE:atlas>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/cook_shipped/${name} ${rel})
  set_tests_properties(cook_shipped_${name} PROPERTIES LABELS graph TIMEOUT 900)
endforeach()
# tests/look/test_cumulus_anatomy.py reads the grown cloudscape this cook writes.
set_tests_properties(cook_shipped_cumulus_cloudscape PROPERTIES FIXTURES_SETUP shipped_cumulus_cloudscape)
add_test(NAME cook_quickstart COMMAND atlas cook "${PROJECT_SOURCE_DIR}/examples/quickstart.yaml"
         --out "${PROJECT_BINARY_DIR}/quickstart-out" --quiet --checked)
set_tests_properties(cook_quickstart PROPERTIES LABELS graph PASS_REGULAR_EXPRESSION "cooked 14, cached 0, skipped 1 nodes")
# The same bytes on the AVX2 and the portable paths (ATLAS_SIMD=scalar), a tiled world (issue 46 item 4).
add_test(NAME portable_simd_tiled_world COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/portable_simd_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/portable_simd)
set_tests_properties(portable_simd_tiled_world PROPERTIES LABELS graph SKIP_RETURN_CODE 77)
