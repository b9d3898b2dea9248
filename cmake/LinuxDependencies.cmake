# Third-party libraries of the Linux programs (the simulated board, drive_hil, drive_monitor
# and the host tools). Native builds use Debian's packages as they are. A static build
# (IMD_STATIC_LINK: the aarch64 cross build, and the programs the qemu tier boots) cannot link
# toml++ and fmt as Debian ships them, shared libraries only: there fmt is used in its
# header-only mode, and toml++'s implementation is compiled once, into a static library, from
# the same headers (in header-only mode every file that reads TOML compiled it again: a minute
# each).
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
if(NOT IMD_STATIC_LINK)
  find_package(tomlplusplus REQUIRED)
  find_package(fmt REQUIRED)
else()
  find_path(IMD_TOMLPP_INCLUDE_DIR toml++/toml.h)
  find_path(IMD_FMT_INCLUDE_DIR fmt/format.h)
  if(NOT IMD_TOMLPP_INCLUDE_DIR OR NOT IMD_FMT_INCLUDE_DIR)
    message(FATAL_ERROR "toml++ or fmt headers not found: install Debian's libtomlplusplus-dev "
                        "and libfmt-dev (tools/install_deps.sh)")
  endif()
  if(NOT TARGET imd_toml_implementation)  # this file is included from more than one directory
    add_library(imd_toml_implementation STATIC ${CMAKE_CURRENT_LIST_DIR}/toml_implementation.cpp)
    target_include_directories(imd_toml_implementation PUBLIC "${IMD_TOMLPP_INCLUDE_DIR}")
    target_compile_definitions(imd_toml_implementation PUBLIC TOML_HEADER_ONLY=0)
    add_library(tomlplusplus::tomlplusplus ALIAS imd_toml_implementation)
  endif()
  add_library(fmt::fmt INTERFACE IMPORTED)
  set_target_properties(fmt::fmt PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${IMD_FMT_INCLUDE_DIR}"
    INTERFACE_COMPILE_DEFINITIONS "FMT_HEADER_ONLY=1")
endif()
