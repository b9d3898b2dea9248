# The Debian package (cmake/Install.cmake): cpack builds it from this build tree, and the tools
# extracted from it run: --version and a short scenario of the installed data, with its plot.
find_program(IMD_DPKG_DEB dpkg-deb)
if(IMD_DPKG_DEB)
  add_test(NAME package_deb_runs
           COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/packaging/check_deb.sh ${CMAKE_BINARY_DIR}
                   ${CMAKE_CURRENT_BINARY_DIR}/package_deb)
  set_tests_properties(package_deb_runs PROPERTIES LABELS sim TIMEOUT 120
                       PASS_REGULAR_EXPRESSION "check_deb: .*installed tools run")
endif()
