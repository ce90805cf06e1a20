# Stored mip levels (texgen.h's "X.mipK.png" contract, PACK.md "mips"):
# `splatc build` copies them into the pack and lists them in the manifest,
# splatview uploads them instead of blitting its own (the picture changes
# when they are taken away), and a level of the wrong size is refused.
# Label gpu: it renders on lavapipe with the validation layer on.
# imgcheck comes from tests/render (same condition), included after this file:
# the generator expression resolves once every target exists.
if(TARGET splatc_cli AND TARGET splatview)
  add_test(NAME mips.stored_levels
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/mips.sh $<TARGET_FILE:splatc_cli>
            $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck> ${CMAKE_BINARY_DIR}/tests/mips
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(mips.stored_levels PROPERTIES LABELS "gpu;mips"
    ENVIRONMENT "SPLAT_VALIDATE=1" TIMEOUT 300)
endif()
