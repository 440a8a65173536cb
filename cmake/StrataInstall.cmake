# Installs the public headers, the module libraries (static) and the CMake package
# strataConfig.cmake + strataConfigVersion.cmake + strataTargets.cmake under
# <prefix>/lib/cmake/strata. Consumers: find_package(strata) and link strata::strata (or one
# module, strata::geometry, strata::io, strata::field, strata::untangle, strata::simplify).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(STRATA_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/strata" CACHE STRING
    "Where the strata CMake package is installed (relative to the prefix)")

get_property(strata_modules GLOBAL PROPERTY STRATA_MODULES)
# strata_warnings/strata_sanitize appear in the modules' link interfaces; they carry no flags
# for consumers (warnings are LINK_ONLY, sanitizers only when the install was built with them).
install(TARGETS strata ${strata_modules} strata_warnings strata_sanitize
        EXPORT strataTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/strata"
        DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(EXPORT strataTargets NAMESPACE strata:: DESTINATION "${STRATA_INSTALL_CMAKEDIR}")

set(STRATA_INSTALL_LIBDIR "${CMAKE_INSTALL_LIBDIR}")  # where libstrata_field_grid.so goes
configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/strataConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/strataConfig.cmake"
  INSTALL_DESTINATION "${STRATA_INSTALL_CMAKEDIR}"
  PATH_VARS STRATA_INSTALL_LIBDIR)
write_basic_package_version_file("${PROJECT_BINARY_DIR}/strataConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/strataConfig.cmake"
              "${PROJECT_BINARY_DIR}/strataConfigVersion.cmake"
        DESTINATION "${STRATA_INSTALL_CMAKEDIR}")
install(TARGETS strata_cli RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
