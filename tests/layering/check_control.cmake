cmake_minimum_required(VERSION 3.25)
# Runs the configure-time layering rules of control/ on the directory this script is run from
# (cmake -P sets CMAKE_CURRENT_SOURCE_DIR to the working directory).
include(${CMAKE_CURRENT_LIST_DIR}/../../cmake/Layering.cmake)
imd_check_layering(control ALLOWED control)
imd_check_control_is_pure(control)
message(STATUS "layering of control/ is clean")
