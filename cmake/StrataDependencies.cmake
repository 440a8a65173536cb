# Finds strata's dependencies, all of them Debian packages (see .ci/install-deps).

find_package(glm REQUIRED)
find_package(Eigen3 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(nlohmann_json 3.2 REQUIRED)
find_package(simdjson 3 REQUIRED)  # the JSON scene reader's fast path (src/io/json_io.cpp)
find_package(CLI11 REQUIRED)
find_package(tinyxml2 REQUIRED)
find_package(Boost 1.74 REQUIRED)
# OpenMesh (Debian libopenmesh-dev 9.0 ships a config without a version file): OpenMeshCore.
find_package(OpenMesh REQUIRED)

# Debian ships OpenVDB's FindOpenVDB.cmake (no config package) under lib/<arch>/cmake/OpenVDB.
if(CMAKE_LIBRARY_ARCHITECTURE)
  list(APPEND CMAKE_MODULE_PATH "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB")
endif()
list(APPEND CMAKE_MODULE_PATH "/usr/lib/cmake/OpenVDB" "/usr/local/lib/cmake/OpenVDB")
find_package(OpenVDB REQUIRED)

# stb is header only (Debian: libstb-dev puts the headers in /usr/include/stb).
find_path(STB_INCLUDE_DIR stb_image_write.h PATH_SUFFIXES stb REQUIRED)
add_library(strata_stb INTERFACE)
target_include_directories(strata_stb SYSTEM INTERFACE "${STB_INCLUDE_DIR}")
