# Render tests (label "render"): headless splatview on lavapipe with
# SPLAT_VALIDATE=1 over a fixture pack written by make_fixture (until
# `splatc build` writes real packs), checked by imgcheck.  run.sh holds the
# cases; each is one CTest.
if(TARGET splatrt AND TARGET splatview)
  set(RENDER_DIR ${CMAKE_CURRENT_LIST_DIR})
  add_executable(make_fixture ${RENDER_DIR}/make_fixture.c)
  target_link_libraries(make_fixture splatrt)
  add_executable(imgcheck ${RENDER_DIR}/imgcheck.c)
  target_link_libraries(imgcheck splatrt)

  set(RENDER_OUT ${CMAKE_BINARY_DIR}/tests/render)
  file(MAKE_DIRECTORY ${RENDER_OUT})
  add_test(NAME render.fixture COMMAND make_fixture ${RENDER_OUT}/fixture)
  set_tests_properties(render.fixture PROPERTIES LABELS render FIXTURES_SETUP render_pack)

  set(RENDER_CASES final combos views reference_multipass reference_uber cracks
      bad_packs stats viewer)
  # these also run under ASan + UBSan (`make test-asan`, label asan): the
  # pack loader on good and bad packs, a frame, the multi-pass reference
  set(RENDER_ASAN final bad_packs reference_multipass)
  foreach(case ${RENDER_CASES})
    add_test(NAME render.${case}
      COMMAND sh ${RENDER_DIR}/run.sh ${case} $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/fixture ${RENDER_OUT}/out)
    set_tests_properties(render.${case} PROPERTIES LABELS render SKIP_RETURN_CODE 77
      FIXTURES_REQUIRED render_pack ENVIRONMENT "SPLAT_VALIDATE=1" TIMEOUT 300)
    if(case IN_LIST RENDER_ASAN)
      set_property(TEST render.${case} APPEND PROPERTY LABELS asan)
    endif()
  endforeach()

  # The same checks on a real pack: examples/minimal through `splatc build`.
  if(TARGET splatc_cli)
    add_test(NAME render.pack_minimal
      COMMAND $<TARGET_FILE:splatc_cli> build ${PROJECT_SOURCE_DIR}/examples/minimal/scene.sg
              -o ${RENDER_OUT}/minimal --no-cache)
    set_tests_properties(render.pack_minimal PROPERTIES LABELS render FIXTURES_SETUP minimal_pack)
    add_test(NAME render.real_minimal
      COMMAND sh ${RENDER_DIR}/run.sh real $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/minimal ${RENDER_OUT}/out)
    set_tests_properties(render.real_minimal PROPERTIES LABELS "render;asan"
      FIXTURES_REQUIRED minimal_pack ENVIRONMENT "SPLAT_VALIDATE=1" TIMEOUT 300)
    # the window on a pack with compute variants: the screen-space path
    add_test(NAME render.viewer_minimal
      COMMAND sh ${RENDER_DIR}/run.sh viewer $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/minimal ${RENDER_OUT}/out_viewer_minimal)
    set_tests_properties(render.viewer_minimal PROPERTIES LABELS render SKIP_RETURN_CODE 77
      FIXTURES_REQUIRED minimal_pack ENVIRONMENT "SPLAT_VALIDATE=1" TIMEOUT 300)
    # the preview scale (runtime/upscale.c): PSNR floors against full
    # resolution on three paths, the depth guide against bilinear
    add_test(NAME render.preview_scale
      COMMAND sh ${RENDER_DIR}/preview_scale.sh $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/minimal ${RENDER_OUT}/preview_scale)
    set_tests_properties(render.preview_scale PROPERTIES LABELS render TIMEOUT 600
      SKIP_RETURN_CODE 77 FIXTURES_REQUIRED minimal_pack)
    # the CPU shading LOD (runtime/DESIGN.md): on against off, the paths
    # with it on, auto on a CPU device
    add_test(NAME render.shading_lod
      COMMAND sh ${RENDER_DIR}/shading_lod.sh $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/colorado ${RENDER_OUT}/shading_lod valley)
    set_tests_properties(render.shading_lod PROPERTIES LABELS render TIMEOUT 900
      FIXTURES_REQUIRED colorado_pack)
    # the help overlay (key H): headless --overlay and the window
    add_test(NAME render.overlay
      COMMAND sh ${RENDER_DIR}/run.sh overlay $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/minimal ${RENDER_OUT}/out)
    set_tests_properties(render.overlay PROPERTIES LABELS render SKIP_RETURN_CODE 77
      FIXTURES_REQUIRED minimal_pack ENVIRONMENT "SPLAT_VALIDATE=1" TIMEOUT 300)
    # hot reload of an edited scene; _search: imports found only through
    # -I or $SPLATC_PATH, as splatc build finds them; _far: the far atlas
    # rebaked on the viewer's device
    foreach(case hot_reload hot_reload_search hot_reload_far preview)
      add_test(NAME render.${case}
        COMMAND sh ${RENDER_DIR}/run.sh ${case} $<TARGET_FILE:splatview>
                $<TARGET_FILE:imgcheck> ${RENDER_OUT}/minimal ${RENDER_OUT}/out)
      set_tests_properties(render.${case} PROPERTIES LABELS render TIMEOUT 300
        SKIP_RETURN_CODE 77
        ENVIRONMENT "SPLAT_VALIDATE=1;SPLATC=$<TARGET_FILE:splatc_cli>")
    endforeach()

    # The example scenes rendered (examples.sh): colorado and billingsley,
    # and billingsley without presets (nocam.sg) for the computed default
    # camera.  Their packs are built first, with a SPIR-V cache in the
    # build tree so reruns are quick.
    set(EXAMPLE_SCENES
      colorado examples/colorado/scene.sg
      billingsley examples/billingsley/scene.sg
      nocam tests/render/nocam.sg)
    while(EXAMPLE_SCENES)
      list(POP_FRONT EXAMPLE_SCENES ex scene)
      add_test(NAME render.pack_${ex}
        COMMAND $<TARGET_FILE:splatc_cli> build ${scene} -o ${RENDER_OUT}/${ex} -j 2
                --cache ${RENDER_OUT}/spv_cache
        WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
      set_tests_properties(render.pack_${ex} PROPERTIES LABELS render TIMEOUT 600
        FIXTURES_SETUP ${ex}_pack)
      add_test(NAME render.example_${ex}
        COMMAND sh ${RENDER_DIR}/examples.sh ${ex} $<TARGET_FILE:splatview>
                $<TARGET_FILE:imgcheck> ${RENDER_OUT}/${ex} ${RENDER_OUT}/out)
      set_tests_properties(render.example_${ex} PROPERTIES LABELS render TIMEOUT 600
        FIXTURES_REQUIRED ${ex}_pack ENVIRONMENT "SPLAT_VALIDATE=1")
    endwhile()

    # Lazy branches: colorado's pack against the same built --no-lazy.
    add_test(NAME render.lazy_colorado
      COMMAND sh ${RENDER_DIR}/lazy.sh $<TARGET_FILE:splatc_cli> $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> ${RENDER_OUT}/colorado ${RENDER_OUT}/spv_cache
              ${RENDER_OUT}/out
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(render.lazy_colorado PROPERTIES LABELS render TIMEOUT 600
      FIXTURES_REQUIRED colorado_pack ENVIRONMENT "SPLAT_VALIDATE=1")

    # The screen-space path against the forward path at every camera
    # preset (screen.sh says what each kind of scene is held to).
    add_test(NAME render.pack_notex
      COMMAND $<TARGET_FILE:splatc_cli> build tests/render/notex.sg -o ${RENDER_OUT}/notex
              --cache ${RENDER_OUT}/spv_cache
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(render.pack_notex PROPERTIES LABELS render FIXTURES_SETUP notex_pack)
    # a spline road and a polygon decal read as vector masks (compiler/vector.c)
    add_test(NAME render.pack_vector
      COMMAND $<TARGET_FILE:splatc_cli> build tests/vector/vector.sg -o ${RENDER_OUT}/vector
              --cache ${RENDER_OUT}/spv_cache
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(render.pack_vector PROPERTIES LABELS render FIXTURES_SETUP vector_pack)
    set(SCREEN_CASES
      "colorado|textured|overview blanca valley spanish_peaks pivots trinidad"
      "billingsley|textured|overview ground peak"
      "minimal|textured|overview"
      "notex|notex|overview low"
      "vector|notex|low overview")
    foreach(sc IN LISTS SCREEN_CASES)
      string(REPLACE "|" ";" f "${sc}")
      list(GET f 0 pk)
      list(GET f 1 kind)
      list(GET f 2 presets)
      separate_arguments(presets)
      add_test(NAME render.screen_${pk}
        COMMAND sh ${RENDER_DIR}/screen.sh $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck>
                ${RENDER_OUT}/${pk} ${RENDER_OUT}/out ${kind} ${presets})
      set_tests_properties(render.screen_${pk} PROPERTIES LABELS render TIMEOUT 1800
        FIXTURES_REQUIRED ${pk}_pack ENVIRONMENT "SPLAT_VALIDATE=1")
      if(pk STREQUAL "minimal")   # the screen path under ASan + UBSan too
        set_property(TEST render.screen_${pk} APPEND PROPERTY LABELS asan)
      endif()
    endforeach()
    # the SPIR-V and pipeline caches across runs (spirv_cache.sh)
    # (and examples/minimal built with --glsl-compute: compute variants the
    # runtime compiles on first use)
    add_test(NAME render.pack_minimal_glsl
      COMMAND $<TARGET_FILE:splatc_cli> build ${PROJECT_SOURCE_DIR}/examples/minimal/scene.sg
              -o ${RENDER_OUT}/minimal_glsl --glsl-compute --no-cache)
    set_tests_properties(render.pack_minimal_glsl PROPERTIES LABELS render
      FIXTURES_SETUP minimal_glsl_pack)
    add_test(NAME render.spirv_cache
      COMMAND sh ${RENDER_DIR}/spirv_cache.sh $<TARGET_FILE:splatview> ${RENDER_OUT}/minimal
              ${RENDER_OUT}/out ${RENDER_OUT}/minimal_glsl)
    set_tests_properties(render.spirv_cache PROPERTIES LABELS "render;asan" TIMEOUT 300
      FIXTURES_REQUIRED "minimal_pack;minimal_glsl_pack")
    # the flat and far-atlas stand-ins of async pipelines: the first
    # picture without the über-shader and without a compile (the pack's
    # stand-in SPIR-V; without it, the GLSL-built one draws the same
    # picture), the final one equal to the synchronous picture once the
    # pipelines land (stand_in.sh)
    add_test(NAME render.stand_in
      COMMAND sh ${RENDER_DIR}/stand_in.sh $<TARGET_FILE:splatc_cli> $<TARGET_FILE:splatview>
              $<TARGET_FILE:imgcheck> $<TARGET_FILE:packedit> ${PROJECT_SOURCE_DIR} ${RENDER_OUT}/out)
    set_tests_properties(render.stand_in PROPERTIES LABELS "render;asan" TIMEOUT 900
      ENVIRONMENT "SPLAT_VALIDATE=1")
    # SPLAT_VALIDATE=1 without the validation layer: a loud failure
    add_test(NAME render.no_validation_layer
      COMMAND sh ${RENDER_DIR}/no_layer.sh $<TARGET_FILE:splatview> ${RENDER_OUT}/minimal
              ${RENDER_OUT}/out)
    set_tests_properties(render.no_validation_layer PROPERTIES LABELS render
      FIXTURES_REQUIRED minimal_pack)
    # craters on the screen path (tests/destruction's pack)
    add_test(NAME render.screen_destruction
      COMMAND sh ${RENDER_DIR}/screen.sh $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck>
              ${CMAKE_BINARY_DIR}/tests/destruction/pack ${RENDER_OUT}/out textured above)
    set_tests_properties(render.screen_destruction PROPERTIES LABELS render TIMEOUT 600
      FIXTURES_REQUIRED destruction_pack ENVIRONMENT "SPLAT_VALIDATE=1;CRATER=60")
  endif()
  # preview lighting: the light block, exposure, sun, view and fog
  # (test_lighting.c builds its own packs of examples/minimal)
  if(TARGET splatc)
    add_executable(test_lighting ${RENDER_DIR}/test_lighting.c)
    target_link_libraries(test_lighting splat_testkit)
    file(MAKE_DIRECTORY ${RENDER_OUT}/lighting)
    add_test(NAME render.lighting COMMAND test_lighting ${RENDER_OUT}/lighting
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(render.lighting PROPERTIES LABELS render TIMEOUT 600
                         ENVIRONMENT "SPLAT_VALIDATE=1")
    # the lighting model against its double twin, on three paths, and the
    # terrain's shadows
    foreach(t brdf shadow undergrowth ug_look ug_cull ug_compute)
      add_executable(test_${t} ${RENDER_DIR}/test_${t}.c)
      target_link_libraries(test_${t} splat_testkit)
      file(MAKE_DIRECTORY ${RENDER_OUT}/${t})
      add_test(NAME render.${t} COMMAND test_${t} ${RENDER_OUT}/${t}
               WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
      set_tests_properties(render.${t} PROPERTIES LABELS render TIMEOUT 600
                           ENVIRONMENT "SPLAT_VALIDATE=1")
    endforeach()
    # far undergrowth blades drawn in compute against the graphics path, the
    # one-pass 64-bit atomics and the two-pass fallback (test_ug_compute.c)
    add_test(NAME render.ug_compute_2pass COMMAND test_ug_compute ${RENDER_OUT}/ug_compute_2pass
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    file(MAKE_DIRECTORY ${RENDER_OUT}/ug_compute_2pass)
    set_tests_properties(render.ug_compute_2pass PROPERTIES LABELS render TIMEOUT 600
                         ENVIRONMENT "SPLAT_VALIDATE=1;SPLAT_UG_ATOMICS=32")
    # the shadow map marched on the device against the CPU reference within
    # 1/255: three suns and a crater (test_shadow_gpu.c)
    add_executable(test_shadow_gpu ${RENDER_DIR}/test_shadow_gpu.c)
    target_link_libraries(test_shadow_gpu splat_testkit)
    file(MAKE_DIRECTORY ${RENDER_OUT}/shadow_gpu)
    add_test(NAME render.shadow_gpu COMMAND test_shadow_gpu ${RENDER_OUT}/shadow_gpu
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(render.shadow_gpu PROPERTIES LABELS "render;gpu;asan" TIMEOUT 600
                         ENVIRONMENT "SPLAT_VALIDATE=1")
    # distance classes against the über-shader at 20 random cameras on
    # colorado, both paths (test_dclass.c)
    add_executable(test_dclass ${RENDER_DIR}/test_dclass.c)
    target_link_libraries(test_dclass splat_testkit)
    add_test(NAME render.dclass COMMAND test_dclass ${RENDER_OUT}/colorado
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(render.dclass PROPERTIES LABELS render TIMEOUT 900
                         FIXTURES_REQUIRED colorado_pack ENVIRONMENT "SPLAT_VALIDATE=1")
    # issue 31, masks without stair steps: snowfield's mask edge at
    # colorado's valley camera follows a smooth curve (stairs.c), in both
    # shading paths
    add_executable(stairs ${RENDER_DIR}/stairs.c)
    target_link_libraries(stairs splatrt m)
    add_test(NAME render.stairs_colorado
             COMMAND sh ${RENDER_DIR}/stairs.sh $<TARGET_FILE:splatview> $<TARGET_FILE:stairs>
                     ${RENDER_OUT}/colorado ${RENDER_OUT}/stairs)
    set_tests_properties(render.stairs_colorado PROPERTIES LABELS render TIMEOUT 600
                         FIXTURES_REQUIRED colorado_pack ENVIRONMENT "SPLAT_VALIDATE=1")
    # the runtime's Vulkan builder: desc defaults that draw, a failure that
    # adds nothing, destroy lists that leave nothing alive (test_vk_build.c)
    add_executable(test_vk_build ${RENDER_DIR}/test_vk_build.c)
    target_link_libraries(test_vk_build splat_testkit splatrt splatc m)
    add_test(NAME render.vk_build COMMAND test_vk_build)
    set_tests_properties(render.vk_build PROPERTIES LABELS "render;asan" TIMEOUT 300
                         ENVIRONMENT "SPLAT_VALIDATE=1")
    # the undergrowth's cells, GPU passes, cull passes and pack sections under the
    # sanitizers too
    set_tests_properties(render.undergrowth render.ug_cull PROPERTIES LABELS "render;asan")
  endif()
endif()
