# Install test (run.sh): `cmake --install` into a temporary prefix, then,
# outside the repository, a scene importing nodes/masks.sg builds with the
# installed splatc and no -I, and a tiny C program links libsplatrt through
# pkg-config and through find_package(splatc).
add_test(NAME install.prefix
         COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/run.sh ${PROJECT_BINARY_DIR}
                 ${CMAKE_CURRENT_LIST_DIR} ${CMAKE_C_COMPILER} ${CMAKE_COMMAND}
                 ${PROJECT_SOURCE_DIR}/examples/minimal/heightfield.png)
set_tests_properties(install.prefix PROPERTIES LABELS install TIMEOUT 900)
