# Install-time script (cmake/Install.cmake): writes IMD_VERSION_TEXT (relative to the install
# prefix) with the version text of the build's generated header IMD_VERSION_HEADER, so that
# the installed Python tools print what the installed C++ tools print.
file(STRINGS "${IMD_VERSION_HEADER}" line REGEX "kText = ")
if(NOT line MATCHES "kText = \"([^\"]+)\"")
  message(FATAL_ERROR "${IMD_VERSION_HEADER}: no version text (build the project first)")
endif()
set(text "${CMAKE_MATCH_1}")
set(destination "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}/${IMD_VERSION_TEXT}")
message(STATUS "Installing: ${destination}")
file(WRITE "${destination}" "${text}\n")
list(APPEND CMAKE_INSTALL_MANIFEST_FILES "${destination}")
