# Installation and the Debian package of the host tools (native Linux builds only).
#
#   cmake --install build --prefix /opt/imdrive     # or any prefix; the tools find their data
#   cd build && cpack                                # build/imdrive_<version>_<arch>.deb
#
# Layout under the prefix (docs/install.md):
#   bin/                                   drive_sim, drive_monitor, drive_hil, dbc_gen,
#                                          drive_model, soak, scenario_embed
#   share/imdrive/scenarios, motors        the scenario and motor files (scenarios name their
#                                          motors as ../motors/NAME.toml, as in the source tree)
#   share/imdrive/tools                    the plot scripts drive_sim runs, with their modules
#   share/imdrive/can/drive.dbc            the CAN protocol for DBC-aware tools
#   share/doc/imdrive                      README.md, docs/ and tools/python/README.md: the
#                                          source tree's layout, so their relative links resolve
#   lib/python3/dist-packages/imdrive      the Python client (Debian's path: with prefix /usr,
#                                          as the .deb installs, python3 finds it unaided);
#   bin/imdrive                            its command line (finds ../lib/python3/dist-packages
#                                          under any prefix)
if(CMAKE_CROSSCOMPILING OR NOT CMAKE_SYSTEM_NAME STREQUAL "Linux")
  return()
endif()
include(GNUInstallDirs)

set(IMD_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/imdrive)
set(IMD_INSTALL_PYTHONDIR lib/python3/dist-packages)

# The tools look for their data relative to their own directory first (tools/data_path.hpp), so
# an installed tree works under any prefix, and fall back to the source tree.
file(RELATIVE_PATH imd_data_from_bin /prefix/${CMAKE_INSTALL_BINDIR}
     /prefix/${IMD_INSTALL_DATADIR})
target_compile_definitions(soak PRIVATE IMD_DATA_DIR_FROM_BIN="${imd_data_from_bin}")
# Without the host tools (the asan preset) there is no package to make.
if(NOT IMD_BUILD_HOST_TOOLS)
  return()
endif()
target_compile_definitions(drive_sim PRIVATE IMD_DATA_DIR_FROM_BIN="${imd_data_from_bin}")

set(imd_tools drive_sim drive_monitor drive_hil dbc_gen drive_model soak scenario_embed)
foreach(tool IN LISTS imd_tools)
  if(TARGET ${tool})
    install(TARGETS ${tool} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()

install(DIRECTORY ${PROJECT_SOURCE_DIR}/hal_sim/scenarios ${PROJECT_SOURCE_DIR}/hal_sim/motors
        DESTINATION ${IMD_INSTALL_DATADIR} FILES_MATCHING PATTERN "*.toml")
install(PROGRAMS ${PROJECT_SOURCE_DIR}/tools/plot_seed000.py
                 ${PROJECT_SOURCE_DIR}/tools/plot_seed001.py
        DESTINATION ${IMD_INSTALL_DATADIR}/tools)
install(FILES ${PROJECT_SOURCE_DIR}/tools/plot_states.py ${PROJECT_SOURCE_DIR}/tools/imd_version.py
        DESTINATION ${IMD_INSTALL_DATADIR}/tools)
# The Python tools' --version: the build's version text beside imd_version.py.
install(CODE "set(IMD_VERSION_HEADER \"${IMD_VERSION_DIR}/imd_version.hpp\")
set(IMD_VERSION_TEXT \"${IMD_INSTALL_DATADIR}/tools/imd_version.txt\")")
install(SCRIPT ${CMAKE_CURRENT_LIST_DIR}/InstallVersionText.cmake)
install(FILES ${PROJECT_SOURCE_DIR}/docs/can/drive.dbc DESTINATION ${IMD_INSTALL_DATADIR}/can)
# The README links docs/... and tools/python/README.md: the same layout under DOCDIR.
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/tools/python/imdrive DESTINATION ${IMD_INSTALL_PYTHONDIR}
        PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)
# ...and its command line as `imdrive` (it puts ../lib/python3/dist-packages on the path).
install(PROGRAMS ${PROJECT_SOURCE_DIR}/tools/python/imdrive_cli.py
        DESTINATION ${CMAKE_INSTALL_BINDIR} RENAME imdrive)
install(FILES ${PROJECT_SOURCE_DIR}/tools/python/README.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/tools/python)

# The Debian package: Debian 12's own libraries, so the tools run from /usr/bin as they are.
# The Python parts are recommended: the C++ tools run without them.
set(IMD_DEB_MAINTAINER "imdrive maintainers <imdrive-maintainers@example.org>"
    CACHE STRING "Maintainer field of the Debian package")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME imdrive)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT ${IMD_DEB_MAINTAINER})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Induction-motor drive: simulator, CAN monitor and host tools")
# One string: set() with several would join them with ';' into the package's text.
string(CONCAT CPACK_PACKAGE_DESCRIPTION
    "The host side of the imdrive induction-motor drive firmware: drive_sim (the firmware on a "
    "simulated board), drive_monitor (watch and command a drive over SocketCAN), drive_hil (the "
    "drive in real time against a simulated motor), the DBC file of the CAN protocol, the "
    "scenario and motor files, and the Python client imdrive.")
set(CPACK_DEBIAN_PACKAGE_SECTION electronics)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# What dpkg-shlibdeps finds in the tools built on Debian 12 (kept as a list, so that packaging
# needs no dpkg-dev).
string(CONCAT CPACK_DEBIAN_PACKAGE_DEPENDS
       "libc6 (>= 2.35), libstdc++6 (>= 11), libgcc-s1 (>= 3.4), libfmt9 (>= 9.1.0+ds1), "
       "libtomlplusplus3 (>= 3.2.0), libgpiod2 (>= 1.1)")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3, python3-numpy, python3-matplotlib, python3-can")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "can-utils, openocd, stlink-tools")
set(CPACK_STRIP_FILES ON)
include(CPack)
