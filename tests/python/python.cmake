# The Python client (tools/python/imdrive) under pytest, and the checks that keep it in step
# with the C++ side: its protocol table is what dbc_gen writes now, its command frames are the
# firmware encoder's bit for bit (e2e_vectors), and its log reader takes drive_sim's CAN logs.
# The interpreter is Debian's, with python3-can, python3-pytest and python3-matplotlib.
set(IMD_PYTHON /usr/bin/python3)
set(IMD_PY_TESTS ${CMAKE_CURRENT_SOURCE_DIR}/python)
set(IMD_PY_WORK ${CMAKE_CURRENT_BINARY_DIR}/python)

add_executable(e2e_vectors ${IMD_PY_TESTS}/e2e_vectors.cpp)
target_link_libraries(e2e_vectors PRIVATE imd_firmware)
target_include_directories(e2e_vectors PRIVATE ${PROJECT_SOURCE_DIR})

# The committed table must be what dbc_gen writes from firmware/protocol/messages.hpp today.
add_test(NAME python_protocol_table_is_current
         COMMAND sh ${IMD_PY_TESTS}/check_table.sh $<TARGET_FILE:dbc_gen> ${PROJECT_SOURCE_DIR}
                 ${IMD_PY_WORK}/protocol_table.py)
set_tests_properties(python_protocol_table_is_current PROPERTIES LABELS unit)

# pytest, one ctest per tier: no bytecode or cache written into the source tree, the package
# imported from tools/python, the programs it needs passed in.
function(imd_pytest NAME LABEL MARKER)
  add_test(NAME ${NAME}
           COMMAND ${IMD_PYTHON} -B -m pytest -q -p no:cacheprovider -m ${MARKER}
                   --drive-sim=$<TARGET_FILE:drive_sim> --e2e-vectors=$<TARGET_FILE:e2e_vectors>
                   --source-dir=${PROJECT_SOURCE_DIR} --basetemp=${IMD_PY_WORK}/${NAME}
                   ${IMD_PY_TESTS})
  # IMD_DRIVE_HIL: the real-time main, served over socketcand (test_socketcand_hil.py).
  set(environment PYTHONDONTWRITEBYTECODE=1 MPLBACKEND=Agg IMD_DRIVE_HIL=$<TARGET_FILE:drive_hil>)
  set_tests_properties(${NAME} PROPERTIES LABELS ${LABEL} TIMEOUT 300
                       ENVIRONMENT "${environment}")
endfunction()
imd_pytest(python_client_unit unit "not sim")
imd_pytest(python_client_sim sim sim)
