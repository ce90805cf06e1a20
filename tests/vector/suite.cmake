# Vector masks (splines and polygons, compiler/vector.c): the GPU's masks
# against the CPU reference at every pixel (probe.sh), and vectors.bin
# refused when it is corrupt (hostile.sh).  Parsing errors are fixtures of
# tests/scene (bad_vector_*.sg); the grid and the analysis bounds are
# tests/unit/test_vector.c; the composites against the über-shader on a
# scene with a spline and a polygon is render.screen_vector.
if(TARGET splatview AND TARGET splatc_cli)
  set(VECTOR_OUT ${CMAKE_CURRENT_BINARY_DIR}/vector)
  file(MAKE_DIRECTORY ${VECTOR_OUT})
  add_executable(probe_check ${CMAKE_CURRENT_LIST_DIR}/probe_check.c)
  target_link_libraries(probe_check splatc splatrt)
  target_include_directories(probe_check PRIVATE ${PROJECT_SOURCE_DIR}/compiler
                             ${PROJECT_SOURCE_DIR}/runtime)
  add_test(NAME vector.pack_probe
    COMMAND $<TARGET_FILE:splatc_cli> build tests/vector/probe.sg -o ${VECTOR_OUT}/probe
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(vector.pack_probe PROPERTIES LABELS render FIXTURES_SETUP vector_probe)
  add_test(NAME vector.probe
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/probe.sh $<TARGET_FILE:splatview>
            $<TARGET_FILE:probe_check> ${VECTOR_OUT}/probe tests/vector/probe.sg ${VECTOR_OUT}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(vector.probe PROPERTIES LABELS render TIMEOUT 600
    FIXTURES_REQUIRED vector_probe)
  add_test(NAME vector.hostile
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/hostile.sh $<TARGET_FILE:splatview>
            ${VECTOR_OUT}/probe ${VECTOR_OUT}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(vector.hostile PROPERTIES LABELS render TIMEOUT 300
    FIXTURES_REQUIRED vector_probe)
endif()
