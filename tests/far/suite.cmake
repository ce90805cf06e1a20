# The far atlas (label "render"): `splatc build --far-atlas=4` on colorado
# twice (byte-identical), the screen path's far shading against the
# composites per distance band within the stated error, the forward path's
# against the screen path's and the composites (and, quick enough for the
# ASan run, both paths' far shading on examples/minimal), zero validation
# messages, the atlas baked on the device against the CPU's (--far-bake),
# and damaged atlases refused (far.sh says what each case holds).
if(TARGET splatrt AND TARGET splatview AND TARGET splatc_cli AND TARGET splatbench)
  set(FAR_OUT ${CMAKE_BINARY_DIR}/tests/far)
  file(MAKE_DIRECTORY ${FAR_OUT})
  foreach(case build error forward small device device_small corrupt)
    add_test(NAME far.${case}
      COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/far.sh ${case} $<TARGET_FILE:splatc_cli>
              $<TARGET_FILE:splatview> $<TARGET_FILE:splatbench> ${PROJECT_SOURCE_DIR} ${FAR_OUT}
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(far.${case} PROPERTIES LABELS render TIMEOUT 900
      ENVIRONMENT "SPLAT_VALIDATE=1")
  endforeach()
  set_tests_properties(far.build PROPERTIES FIXTURES_SETUP far_pack)
  set_tests_properties(far.error far.forward far.device PROPERTIES FIXTURES_REQUIRED far_pack)
  set_property(TEST far.small far.device_small far.corrupt APPEND PROPERTY LABELS asan)
endif()
