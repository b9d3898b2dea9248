# Include-layering rules, checked when CMake configures the project.
# A module that includes a project module it may not depend on stops the configure step with
# an error naming the file and the include. tests/layering runs the same rules on fixtures.

set(IMD_PROJECT_MODULES control hal hal_sim firmware tools tests)

# Returns in OUT_VAR the list of "file: include line" entries of DIR that include a project
# module outside ALLOWED. Subfolders named in EXCLUDE have rules of their own.
function(imd_find_layering_violations DIR OUT_VAR)
  cmake_parse_arguments(ARG "" "" "ALLOWED;EXCLUDE" ${ARGN})
  file(GLOB_RECURSE sources "${DIR}/*.hpp" "${DIR}/*.cpp" "${DIR}/*.h" "${DIR}/*.cc")
  foreach(excluded IN LISTS ARG_EXCLUDE)
    list(FILTER sources EXCLUDE REGEX "^${DIR}/${excluded}/")
  endforeach()
  set(violations "")
  foreach(source IN LISTS sources)
    file(STRINGS "${source}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
    foreach(line IN LISTS includes)
      # A relative climb ("../hal/x.hpp", "control/../hal/x.hpp") would hide the module.
      if(line MATCHES "\\.\\.")
        list(APPEND violations "${source}: ${line}")
        continue()
      endif()
      string(REGEX MATCH "[<\"]([A-Za-z_0-9]+)/" _ "${line}")
      set(module "${CMAKE_MATCH_1}")
      if(module AND module IN_LIST IMD_PROJECT_MODULES AND NOT module IN_LIST ARG_ALLOWED)
        list(APPEND violations "${source}: ${line}")
      endif()
    endforeach()
  endforeach()
  set(${OUT_VAR} "${violations}" PARENT_SCOPE)
endfunction()

# Returns in OUT_VAR the includes of DIR that are neither DIR's own headers, nor Eigen, nor a
# C++ standard header (a name without '/' or '.').
function(imd_find_impure_includes DIR OUT_VAR)
  get_filename_component(self "${DIR}" NAME)
  file(GLOB_RECURSE sources "${DIR}/*.hpp" "${DIR}/*.cpp" "${DIR}/*.h" "${DIR}/*.cc")
  set(violations "")
  foreach(source IN LISTS sources)
    file(STRINGS "${source}" includes REGEX "^[ \t]*#[ \t]*include")
    foreach(line IN LISTS includes)
      if(line MATCHES "\\.\\.")
        list(APPEND violations "${source}: ${line}")
        continue()
      endif()
      if(line MATCHES "include[ \t]*\"${self}/"
         OR line MATCHES "include[ \t]*<(unsupported/)?Eigen/"
         OR line MATCHES "include[ \t]*<[a-z_0-9]+>")
        continue()
      endif()
      list(APPEND violations "${source}: ${line}")
    endforeach()
  endforeach()
  set(${OUT_VAR} "${violations}" PARENT_SCOPE)
endfunction()

function(imd_check_layering MODULE)
  imd_find_layering_violations("${CMAKE_CURRENT_SOURCE_DIR}/${MODULE}" violations ${ARGN})
  if(violations)
    list(JOIN violations "\n  " text)
    message(FATAL_ERROR "Layering violation: ${MODULE}/ includes a module it may not depend on:\n  ${text}")
  endif()
endfunction()

function(imd_check_control_is_pure MODULE)
  imd_find_impure_includes("${CMAKE_CURRENT_SOURCE_DIR}/${MODULE}" violations)
  if(violations)
    list(JOIN violations "\n  " text)
    message(FATAL_ERROR "Layering violation: ${MODULE}/ may include only itself, Eigen and the standard library:\n  ${text}")
  endif()
endfunction()
