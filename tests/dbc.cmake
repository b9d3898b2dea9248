# DBC tests: the committed DBC file and protocol reference are current, dbc_gen rejects bad
# input, and a DBC parser this project did not write (candied, tools/dbc_check) loads the file
# and decodes a hand-computed log to the expected physical values.
add_test(NAME dbc_committed_files_are_current
         COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/dbc/check_generated.sh $<TARGET_FILE:dbc_gen>
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/dbc_generated)
set_tests_properties(dbc_committed_files_are_current PROPERTIES LABELS unit)

# An existing file as a parent directory: unwritable even for root.
set(DBC_UNWRITABLE ${CMAKE_CURRENT_SOURCE_DIR}/dbc.cmake/drive.dbc)
imd_tool_test(dbc_gen dbc_gen_help 0 "--markdown" --help)
imd_tool_test(dbc_gen dbc_gen_stdout_node_0 0 "BO_ 2 heartbeat: 8 Drive" --node 0)
imd_tool_test(dbc_gen dbc_gen_node_63 0 "BO_ 2018 heartbeat: 8 Drive" --node 63)
imd_tool_test(dbc_gen dbc_gen_node_too_large 2 "--node: must be a node id in 0..63, got 64"
              --node 64)
imd_tool_test(dbc_gen dbc_gen_node_negative 2 "--node: must be a node id in 0..63, got -1"
              --node=-1)
imd_tool_test(dbc_gen dbc_gen_node_text 2 "--node: must be a node id in 0..63, got one"
              --node one)
imd_tool_test(dbc_gen dbc_gen_version 0 "^VERSION \"[0-9]+\"$" --node 1)
imd_tool_test(dbc_gen dbc_gen_nodes 0 "BU_: Drive1 Drive2 Drive5 Host" --nodes 1,2,5)
imd_tool_test(dbc_gen dbc_gen_nodes_suffixed 0 "BO_ 162 heartbeat_5: 8 Drive5" --nodes 1,2,5)
imd_tool_test(dbc_gen dbc_gen_nodes_twice 2 "--nodes: each node id once" --nodes 1,2,1)
imd_tool_test(dbc_gen dbc_gen_nodes_too_large 2 "--nodes: must be a node id in 0..63, got 64"
              --nodes 1,64)
imd_tool_test(dbc_gen dbc_gen_nodes_and_node 2 "--node excludes --nodes" --nodes 1,2 --node 3)
imd_tool_test(dbc_gen dbc_gen_nodes_markdown 2 "--markdown describes one node"
              --nodes 1,2 --markdown ${CMAKE_CURRENT_BINARY_DIR}/dbc_gen_nodes.md)
imd_tool_test(dbc_gen dbc_gen_unwritable_output 2
              "dbc_gen: --output .*/dbc.cmake/drive.dbc: cannot write the file \\(Not a directory\\)"
              --output ${DBC_UNWRITABLE})
imd_tool_test(dbc_gen dbc_gen_unwritable_markdown 2
              "dbc_gen: --markdown .*/dbc.cmake/messages.md: cannot write the file"
              --output ${CMAKE_CURRENT_BINARY_DIR}/dbc_gen_test.dbc
              --markdown ${CMAKE_CURRENT_SOURCE_DIR}/dbc.cmake/messages.md)

# candied decodes tests/data/can/sample.log (frames computed by hand from the message table)
# with the committed DBC file to the values of sample_expected.csv. run.sh installs Node.js and
# candied when missing, and fails, saying why, when it cannot: this test never skips.
add_test(NAME dbc_third_party_parses
         COMMAND ${EXPECT} 0 "decode_log: all 70 values match"
                 ${PROJECT_SOURCE_DIR}/tools/dbc_check/run.sh ${PROJECT_SOURCE_DIR}/docs/can/drive.dbc
                 ${CMAKE_CURRENT_SOURCE_DIR}/data/can/sample.log
                 --csv ${CMAKE_CURRENT_BINARY_DIR}/dbc_sample_decoded.csv
                 --expect ${CMAKE_CURRENT_SOURCE_DIR}/data/can/sample_expected.csv)
set_tests_properties(dbc_third_party_parses PROPERTIES LABELS unit TIMEOUT 900)

# The same parser loads a DBC file for three drives on one bus (dbc_gen --nodes 1,2,5) cleanly
# and decodes each drive's frames, the version frame among them, under its own names
# (sample_nodes_expected.csv, computed by hand).
add_test(NAME dbc_third_party_parses_nodes
         COMMAND ${EXPECT} 0 "decode_log: all 60 values match"
                 sh -c "\"$1\" --nodes 1,2,5 --output \"$2\" && shift 2 && exec \"$@\""
                 sh $<TARGET_FILE:dbc_gen> ${CMAKE_CURRENT_BINARY_DIR}/dbc_nodes.dbc
                 ${PROJECT_SOURCE_DIR}/tools/dbc_check/run.sh
                 ${CMAKE_CURRENT_BINARY_DIR}/dbc_nodes.dbc
                 ${CMAKE_CURRENT_SOURCE_DIR}/data/can/sample_nodes.log
                 --csv ${CMAKE_CURRENT_BINARY_DIR}/dbc_nodes_decoded.csv
                 --expect ${CMAKE_CURRENT_SOURCE_DIR}/data/can/sample_nodes_expected.csv)
set_tests_properties(dbc_third_party_parses_nodes PROPERTIES LABELS unit TIMEOUT 900)

# One bit rate: the firmware's kNominalBitrate_bit_s, the DBC's Baudrate and every bit-rate
# statement in README.md and docs/ (globbed: new pages are checked too) agree; and the checker
# does catch a page that disagrees.
add_test(NAME dbc_bit_rate_agrees
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/dbc/check_bit_rate.py
                 ${PROJECT_SOURCE_DIR})
set_tests_properties(dbc_bit_rate_agrees PROPERTIES LABELS unit)
add_test(NAME dbc_bit_rate_catches_a_disagreement
         COMMAND ${EXPECT} 1 "wrong_bit_rate.md:3: \"500 kbit/s\", but .* says 1 Mbit/s"
                 /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/dbc/check_bit_rate.py
                 ${PROJECT_SOURCE_DIR} --also ${CMAKE_CURRENT_SOURCE_DIR}/dbc/wrong_bit_rate.md)
set_tests_properties(dbc_bit_rate_catches_a_disagreement PROPERTIES LABELS unit)
