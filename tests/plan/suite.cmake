# The frame plan (label "render"): `splatview --print-plan` on
# examples/minimal built with a far atlas, for the forward, screen, far,
# multi-pass, ray-cast and counting cases: the passes in order and what
# each reads and writes; with --stats each GPU pass's time; Vulkan
# validation (synchronization checks on) silent, and speaking when the
# plan's barriers are left out (SPLAT_PLAN_BARRIERS=0).  plan.sh says more.
if(TARGET splatview AND TARGET splatc_cli)
  add_test(NAME render.plan
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/plan.sh $<TARGET_FILE:splatc_cli>
            $<TARGET_FILE:splatview> ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR}/tests/plan)
  set_tests_properties(render.plan PROPERTIES LABELS render TIMEOUT 300
    ENVIRONMENT "SPLAT_VALIDATE=1")
endif()
