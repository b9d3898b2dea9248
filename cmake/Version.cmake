# The project's version and the git commit it is built from, for every program and image:
# `imd_version` is an interface library whose header <imd_version.hpp> holds both. The header
# is rewritten at build time, and only when the commit (or a dirty tree) changes, so a new
# commit shows in the next build without reconfiguring and without rebuilding everything.
set(IMD_VERSION_DIR ${CMAKE_BINARY_DIR}/generated)
add_custom_target(imd_version_header
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
          -DOUTPUT=${IMD_VERSION_DIR}/imd_version.hpp
          -DVERSION_MAJOR=${PROJECT_VERSION_MAJOR} -DVERSION_MINOR=${PROJECT_VERSION_MINOR}
          -DVERSION_PATCH=${PROJECT_VERSION_PATCH}
          -P ${PROJECT_SOURCE_DIR}/cmake/WriteVersion.cmake
  BYPRODUCTS ${IMD_VERSION_DIR}/imd_version.hpp
  COMMENT "Version header"
  VERBATIM)
add_library(imd_version INTERFACE)
target_include_directories(imd_version INTERFACE ${IMD_VERSION_DIR})
add_dependencies(imd_version imd_version_header)
