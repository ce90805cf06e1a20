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

# No call cycle among the runtime's object files (nm on libsplatrt.a: A
# calls B when A uses a symbol B defines).  async_compile <-> pipelines is
# known and left for now: the workers make pipelines through pipelines.c,
# which starts and asks them.
find_program(NM_PROGRAM nm)
find_program(PYTHON3_PROGRAM python3)
if(TARGET splatrt AND NM_PROGRAM AND PYTHON3_PROGRAM)
  add_test(NAME runtime.cycles
    COMMAND ${PYTHON3_PROGRAM} ${CMAKE_CURRENT_LIST_DIR}/cycles.py $<TARGET_FILE:splatrt>
            async_compile,pipelines)
  set_tests_properties(runtime.cycles PROPERTIES LABELS unit)
endif()
