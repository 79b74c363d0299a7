# Every production graph and example must stay valid: `atlas validate` on each
# (cheap: nothing is cooked), and the quickstart is cooked for real.
file(GLOB ATLAS_GRAPH_FILES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/graphs/*.yaml" "${PROJECT_SOURCE_DIR}/examples/*.yaml")
foreach(graph IN LISTS ATLAS_GRAPH_FILES)
  get_filename_component(name "${graph}" NAME_WE)
  add_test(NAME validate_${name} COMMAND atlas validate "${graph}")
  set_tests_properties(validate_${name} PROPERTIES LABELS graph)
endforeach()
add_test(NAME cook_quickstart COMMAND atlas cook "${PROJECT_SOURCE_DIR}/examples/quickstart.yaml"
         --out "${PROJECT_BINARY_DIR}/quickstart-out" --quiet --checked)
set_tests_properties(cook_quickstart PROPERTIES LABELS graph PASS_REGULAR_EXPRESSION "cooked 9, cached 0, skipped 1 nodes")
