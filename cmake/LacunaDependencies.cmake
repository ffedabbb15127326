# Finds the Debian 12 packages Lacuna builds on. OpenVDB ships only a Find module, lib3mf and
# TetGen ship no CMake files at all; see the notes in README.md.

list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB /usr/lib/cmake/OpenVDB)

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(ZLIB REQUIRED)  # compressed PNG pictures

# FindOpenVDB switches BUILD_SHARED_LIBS on in the calling scope; keep our own setting.
set(_lacuna_shared "${BUILD_SHARED_LIBS}")
find_package(OpenVDB REQUIRED)
set(BUILD_SHARED_LIBS "${_lacuna_shared}")

find_package(CGAL REQUIRED)
include(CGAL_TBB_support)
find_package(draco REQUIRED CONFIG)

find_path(LIB3MF_INCLUDE_DIR Model/COM/NMR_DLLInterfaces.h PATH_SUFFIXES lib3mf REQUIRED)
find_library(LIB3MF_LIBRARY NAMES 3MF lib3MF REQUIRED)
add_library(lacuna::lib3mf UNKNOWN IMPORTED)
set_target_properties(lacuna::lib3mf PROPERTIES
  IMPORTED_LOCATION "${LIB3MF_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${LIB3MF_INCLUDE_DIR}")

find_path(TETGEN_INCLUDE_DIR tetgen.h REQUIRED)
find_library(TETGEN_LIBRARY NAMES tet REQUIRED)
add_library(lacuna::tetgen UNKNOWN IMPORTED)
set_target_properties(lacuna::tetgen PROPERTIES
  IMPORTED_LOCATION "${TETGEN_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${TETGEN_INCLUDE_DIR}"
  INTERFACE_COMPILE_DEFINITIONS TETLIBRARY)

# libzip (lib3mf's own dependency): the 3MF reader scans model parts before lib3mf parses them.
find_path(LIBZIP_INCLUDE_DIR zip.h REQUIRED)
find_library(LIBZIP_LIBRARY NAMES zip REQUIRED)
add_library(lacuna::libzip UNKNOWN IMPORTED)
set_target_properties(lacuna::libzip PROPERTIES
  IMPORTED_LOCATION "${LIBZIP_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${LIBZIP_INCLUDE_DIR}")
