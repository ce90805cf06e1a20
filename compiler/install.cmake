# cmake --install: splatc and splatview, libsplatc and libsplatrt (static),
# their public headers under include/splatc, pkg-config files (splatc.pc,
# splatrt.pc), a CMake package (find_package(splatc): splatc::splatc,
# splatc::splatrt) and the node library under share/splatc/nodes, where an
# installed splatc finds it by default (search.c).
# libsplatc's one public header (splatc.h: version, diagnostics, sg_load,
# the build) and libsplatrt's (splatrt.h) with the compiler headers it
# includes (abi.h: the pack's ABI; rt_device and rt_pack are opaque, so
# nothing else).  The compiler's other headers are internal.
set(SPLAT_PUBLIC_HEADERS ${PROJECT_SOURCE_DIR}/compiler/splatc.h)
set(SPLAT_RUNTIME_PUBLIC_HEADERS
  ${PROJECT_SOURCE_DIR}/runtime/splatrt.h ${PROJECT_SOURCE_DIR}/compiler/abi.h)

install(TARGETS splatc_cli splatview RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS splatc splatrt EXPORT splatcTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/splatc)
install(FILES ${SPLAT_PUBLIC_HEADERS} ${SPLAT_RUNTIME_PUBLIC_HEADERS}
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/splatc)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/nodes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/splatc/nodes
        FILES_MATCHING PATTERN "*.sg")

# CMake package.  The targets link glslang, SPIRV-Tools, jansson, xxhash,
# stb, Vulkan and GLFW through their own packages: the config finds them.
set(SPLAT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/splatc)
install(EXPORT splatcTargets NAMESPACE splatc:: DESTINATION ${SPLAT_CMAKE_DIR})
include(CMakePackageConfigHelpers)
configure_package_config_file(${PROJECT_SOURCE_DIR}/compiler/splatcConfig.cmake.in
  ${PROJECT_BINARY_DIR}/splatcConfig.cmake INSTALL_DESTINATION ${SPLAT_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/splatcConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/splatcConfig.cmake
              ${PROJECT_BINARY_DIR}/splatcConfigVersion.cmake DESTINATION ${SPLAT_CMAKE_DIR})

# pkg-config.  The libraries are static, so Libs names everything they
# need, in link order (glslang's and SPIRV-Tools' Debian packages ship
# static archives and no .pc files).
set(SPLAT_PC_COMPILER_LIBS "-lglslang-default-resource-limits -lSPIRV -lglslang -lMachineIndependent -lOGLCompiler -lOSDependent -lGenericCodeGen -lSPIRV-Tools-opt -lSPIRV-Tools -lstdc++ -lpthread -lm")
# Relocatable: the prefix is found from the .pc file's own folder, so an
# install with `cmake --install --prefix P` works wherever P is.
file(RELATIVE_PATH SPLAT_PC_UP /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
foreach(pc splatc splatrt)
  configure_file(${PROJECT_SOURCE_DIR}/compiler/${pc}.pc.in ${PROJECT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
