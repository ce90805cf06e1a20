# Sparse painted masks on a Vulkan device (lavapipe here): the GLSL sampler
# with the real texture formats against the CPU twin and the raster's
# bilinear reference.  Label `gpu`.  Included by tests/CMakeLists.txt.
add_executable(gpu_sparse ${CMAKE_CURRENT_LIST_DIR}/gpu_sparse.c)
target_link_libraries(gpu_sparse splatrt m)
add_test(NAME gpu.sparse COMMAND gpu_sparse WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(gpu.sparse PROPERTIES LABELS gpu TIMEOUT 600
                     ENVIRONMENT SPLAT_VALIDATE=1)
