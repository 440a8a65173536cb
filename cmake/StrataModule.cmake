include(GNUInstallDirs)

# strata_add_module(NAME SOURCES ... DEPENDS ...): a static library of one module.
function(strata_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC
    "$<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>"
    "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>"
    PRIVATE "${PROJECT_SOURCE_DIR}/src")
  target_compile_features(${name} PUBLIC cxx_std_17)
  target_link_libraries(${name} PUBLIC ${ARG_DEPENDS} strata_sanitize
                        PRIVATE ${ARG_PRIVATE_DEPENDS} strata_warnings)
  # Installed as strata::<module> (strata_geometry -> strata::geometry); see cmake/StrataInstall.cmake.
  string(REGEX REPLACE "^strata_" "" export_name "${name}")
  set_target_properties(${name} PROPERTIES EXPORT_NAME "${export_name}")
  add_library(strata::${export_name} ALIAS ${name})
  set_property(GLOBAL APPEND PROPERTY STRATA_MODULES ${name})
endfunction()
