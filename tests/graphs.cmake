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
# Shipped graphs cooked in tiles (1x1, 2x2, 3x2, assembled) at reduced sizes: every file the
# untiled cook's bytes (issue 46 item 2). atlas-dask does the same for the cloudscape (dask_driver).
add_test(NAME shipped_tiles_cloudscape COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/cloudscape graphs/cloudscape.yaml --set "world.resolution=[96,96,32]")
add_test(NAME shipped_tiles_towering_cumulus COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/towering_cumulus graphs/towering_cumulus.yaml
         --set "density.resolution=[96,96,72]")
# The solver graphs at their quick size (the solver cooked whole once per process and cropped);
# the Straka density current is one cell thick in y.
foreach(name cumulus_growth periodic_cumulus_field)
  add_test(NAME shipped_tiles_${name} COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/${name} graphs/${name}.yaml
           --set "cloud.resolution=[32,32,32]" --set cloud.dx=125)
  set_tests_properties(shipped_tiles_${name} PROPERTIES LABELS graph TIMEOUT 600 ENVIRONMENT "TILES=1,1 2,2 4,2")
endforeach()
add_test(NAME shipped_tiles_straka_density_current COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/straka_density_current graphs/straka_density_current.yaml)
set_tests_properties(shipped_tiles_straka_density_current PROPERTIES LABELS graph TIMEOUT 600 ENVIRONMENT "TILES=4,1;MIN_FILES=2")
# The quickstart: its cumulus (288 x 288) tiles, its coverage chain (128 x 128, a grid of its own that
# the cumulus never reads as a field) is cooked whole and written whole.
add_test(NAME shipped_tiles_quickstart COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/quickstart examples/quickstart.yaml)
set_tests_properties(shipped_tiles_quickstart PROPERTIES LABELS graph TIMEOUT 600)
# The grown cloudscape reads the quick tower the cook_shipped fixture grows; the solver sequence
# at its quick size (the solver is cooked whole, once per process, and cropped).
add_test(NAME shipped_tiles_cumulus_cloudscape COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/cumulus_cloudscape graphs/cumulus_cloudscape.yaml
         --set "tower.file=${PROJECT_BINARY_DIR}/cook_shipped/cumulus_cloudscape/graphs/cumulus_out/cumulus_final.vdb"
         --set "world.resolution=[64,64,56]" --set "tower_a.resolution=[64,64,56]" --set "tower_b.resolution=[64,64,56]"
         --set "clouds.resolution=[64,64,56]")
add_test(NAME shipped_tiles_cumulus_side_view COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/cumulus_side_view graphs/cumulus_side_view.yaml
         --set "frame.file=${PROJECT_BINARY_DIR}/cook_shipped/cumulus_cloudscape/graphs/cumulus_out/cumulus/cloud.0006.vdb")
set_tests_properties(shipped_tiles_cumulus_cloudscape shipped_tiles_cumulus_side_view PROPERTIES FIXTURES_REQUIRED shipped_cumulus_cloudscape)
add_test(NAME shipped_tiles_cumulus_sequence COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
         ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/cumulus_sequence graphs/cumulus_sequence.yaml
         --set "cloud.resolution=[32,32,32]" --set cloud.dx=125)
set_tests_properties(shipped_tiles_cloudscape shipped_tiles_towering_cumulus shipped_tiles_cumulus_cloudscape shipped_tiles_cumulus_sequence
                     shipped_tiles_cumulus_side_view PROPERTIES LABELS graph TIMEOUT 600)
set_tests_properties(shipped_tiles_cumulus_cloudscape shipped_tiles_cumulus_sequence PROPERTIES ENVIRONMENT "TILES=1,1 2,2 4,2")
set_tests_properties(shipped_tiles_cumulus_side_view PROPERTIES ENVIRONMENT "TILES=1,1 2,2 4,2;MIN_FILES=1")
# The 2D graphs and the noise sets at full size (a second each; the noise sets some 15 s): map-wide nodes cooked whole and cropped, outputs on
# grids of their own (LUTs, the baked volume, the cirrus textures, the ring table) written whole.
foreach(name superstorm superstorm_lifecycle envelope_mountain hzd_weather fc6_forecast sky_layer nubis_noise hzd_noise)
  add_test(NAME shipped_tiles_${name} COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/cli/shipped_tiles_test.sh $<TARGET_FILE:atlas>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/shipped_tiles/${name} graphs/${name}.yaml)
  set_tests_properties(shipped_tiles_${name} PROPERTIES LABELS graph TIMEOUT 600 ENVIRONMENT "TILES=1,1 2,2 4,2")
endforeach()
# The noise sets write 134 and 9 files per cook (100 s under the sanitizers with three tilings): one.
set_tests_properties(shipped_tiles_nubis_noise shipped_tiles_hzd_noise PROPERTIES ENVIRONMENT "TILES=4,2")
