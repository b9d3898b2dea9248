# The host programs' tests (IMD_BUILD_HOST_TOOLS): drive_model's and drive_sim's command lines
# (output on good input, exit code 2 and a clear message on bad input), the CAN round trip,
# drive_monitor over socketcand and the embedded scenarios. EXPECT, SEED000 and imd_tool_test
# come from tests/CMakeLists.txt.
function(imd_cli_test NAME CODE PATTERN)
  imd_tool_test(drive_model ${NAME} ${CODE} ${PATTERN} ${ARGN})
endfunction()
imd_cli_test(drive_model_discretize 0 "\"eta1\": " discretize --motor ${SEED000})
imd_cli_test(drive_model_help 0 "--sample-period-s" discretize --help)
imd_cli_test(drive_model_no_subcommand 2 "A subcommand is required")
imd_cli_test(drive_model_no_motor 2 "--motor is required" discretize)
imd_cli_test(drive_model_missing_file 2 "drive_model: /nonexistent.toml: cannot open file"
             discretize --motor /nonexistent.toml)
imd_cli_test(drive_model_bad_value 2 "motor.Rs_Ohm = -1: must be > 0"
             discretize --motor ${CMAKE_CURRENT_SOURCE_DIR}/data/motors/bad_negative_Rs.toml)
imd_cli_test(drive_model_negative_period 2 "must be a period in \\(0, 1\\] s, got -1"
             discretize --motor ${SEED000} --sample-period-s -1)
imd_cli_test(drive_model_nan_period 2 "must be a period in \\(0, 1\\] s, got nan"
             discretize --motor ${SEED000} --control-period-s nan)
imd_cli_test(drive_model_text_period 2 "sample-period-s.*must be a number, got fast"
             discretize --motor ${SEED000} --sample-period-s fast)
imd_cli_test(drive_model_unknown_option 2 "--frobnicate"
             discretize --motor ${SEED000} --frobnicate)

# drive_sim: exit code 2 and a clear message on bad input.
set(PAPER ${PROJECT_SOURCE_DIR}/hal_sim/scenarios/seed000_paper.toml)
function(imd_sim_cli_test NAME CODE PATTERN)
  imd_tool_test(drive_sim ${NAME} ${CODE} ${PATTERN} ${ARGN})
endfunction()
imd_sim_cli_test(drive_sim_help 0 "--set" --help)
imd_sim_cli_test(drive_sim_no_scenario 2 "scenario is required")
imd_sim_cli_test(drive_sim_unknown_key 2 "drive_sim: .*unknown key simulation.foo" ${PAPER} --set simulation.foo=1)
imd_sim_cli_test(drive_sim_bad_duration 2 "duration-s" ${PAPER} --duration-s -3)
imd_sim_cli_test(drive_sim_missing_file 2 "cannot open file" /nonexistent.toml)
imd_sim_cli_test(drive_sim_short_run 0 "\"speed_max_err_rad_s\"" ${PAPER} --duration-s 0.05)
# An output that cannot be written (a full disk): exit code 1, the file named, and the run's
# summary still printed.
foreach(flag csv can-log)
  imd_sim_cli_test(drive_sim_${flag}_disk_full 1
                   "^drive_sim: cannot write /dev/full \\(disk full\\?\\)$"
                   ${PAPER} --duration-s 0.05 --${flag} /dev/full)
  imd_sim_cli_test(drive_sim_${flag}_disk_full_summary 1 "\"speed_max_err_rad_s\""
                   ${PAPER} --duration-s 0.05 --${flag} /dev/full)
endforeach()
imd_sim_cli_test(drive_sim_negative_duration 2
                 "--duration-s: -1 s: the simulated time must be > 0 and at most 3600 s"
                 ${PAPER} --duration-s -1)
imd_sim_cli_test(drive_sim_set_fraction 2
                 "^drive_sim: --set can.telemetry_rate_Hz=100.5: .*= 100.5: must be an integer"
                 ${PAPER} --set can.telemetry_rate_Hz=100.5)
# --plot is checked before the run: the format, and python3 with matplotlib (a stand-in module
# on PYTHONPATH makes the import fail). Neither run starts: the progress line never shows.
imd_sim_cli_test(drive_sim_plot_format 2 "^drive_sim: --plot run.txt: the file name must end in"
                 ${PAPER} --plot run.txt)
add_test(NAME drive_sim_plot_without_matplotlib
         COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${CMAKE_CURRENT_SOURCE_DIR}/cli/no_matplotlib
                 ${EXPECT} 2 "^drive_sim: --plot run.png: needs /usr/bin/python3 with matplotlib"
                 $<TARGET_FILE:drive_sim> ${PAPER} --plot run.png)
set_tests_properties(drive_sim_plot_without_matplotlib PROPERTIES LABELS unit)
# The extension in any case: out.PNG passes the format check and stops at the stand-in module.
add_test(NAME drive_sim_plot_upper_case_extension
         COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${CMAKE_CURRENT_SOURCE_DIR}/cli/no_matplotlib
                 ${EXPECT} 2 "^drive_sim: --plot out.PNG: needs /usr/bin/python3 with matplotlib"
                 $<TARGET_FILE:drive_sim> ${PAPER} --plot out.PNG)
set_tests_properties(drive_sim_plot_upper_case_extension PROPERTIES LABELS unit)
# Every output's directory is checked before the run (exit 2), not when it ends.
foreach(flag plot csv summary-json can-log)
  imd_sim_cli_test(drive_sim_${flag}_missing_directory 2
                   "^drive_sim: --${flag} /nonexistent/out.png: no directory /nonexistent$"
                   ${PAPER} --${flag} /nonexistent/out.png)
endforeach()
# A value from the command line that breaks a rule with a key of the file is named as such.
imd_sim_cli_test(drive_sim_duration_names_the_flag 2
                 "metrics.settle_s: = 0.01: must be below simulation.duration_s \\(0.005\\). simulation.duration_s comes from --duration-s 0.005: change it there, or --set metrics.settle_s=VALUE"
                 ${PAPER} --duration-s 0.005)
imd_sim_cli_test(drive_sim_motor_file_missing 2
                 "--motor-file: nosuch.toml: no such file \\(a relative path is taken from the working directory"
                 ${PAPER} --motor-file nosuch.toml)
set(IDENTIFY ${PROJECT_SOURCE_DIR}/hal_sim/scenarios/identify.toml)
imd_sim_cli_test(drive_sim_motor_out_needs_commissioning 2 "--motor-out needs a commissioning"
                 ${PAPER} --motor-out ${CMAKE_CURRENT_BINARY_DIR}/never.toml)
imd_sim_cli_test(drive_sim_bad_motor_file 2 "bad_negative_Rs.toml.*Rs_Ohm" ${PAPER} --motor-file
                 ${PROJECT_SOURCE_DIR}/tests/data/motors/bad_negative_Rs.toml)
imd_sim_cli_test(drive_sim_motor_file_in_commissioning 2 "gives the drive no motor" ${IDENTIFY}
                 --motor-file ${SEED000})
# A commissioning cut short identifies nothing: exit 3, the reason, and no motor file.
imd_sim_cli_test(drive_sim_identification_cut_short 3 "did not end within simulation.duration_s" ${IDENTIFY}
                 --duration-s 1 --motor-out ${CMAKE_CURRENT_BINARY_DIR}/cut_short.toml)
# The whole commissioning: a motor file drive_model reads back.
add_test(NAME drive_sim_identifies_a_motor_file
         COMMAND sh -c "$<TARGET_FILE:drive_sim> ${IDENTIFY} --set identify.rotate=false --motor-out ${CMAKE_CURRENT_BINARY_DIR}/identified.toml > /dev/null && $<TARGET_FILE:drive_model> discretize --motor ${CMAKE_CURRENT_BINARY_DIR}/identified.toml")
set_tests_properties(drive_sim_identifies_a_motor_file PROPERTIES LABELS sim
                     PASS_REGULAR_EXPRESSION "\"eta1\": ")

# The CAN round trip: a simulated run's CAN log decoded by drive_monitor matches the simulator's
# CSV within the telemetry scaling, and candied decodes the same log to the same values.
add_test(NAME can_round_trip
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/can/round_trip.py
                 $<TARGET_FILE:drive_sim> $<TARGET_FILE:drive_monitor> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/can_round_trip)
set_tests_properties(can_round_trip PROPERTIES LABELS sim)

# drive_monitor over socketcand: send and watch against the real drive_hil served on TCP.
add_test(NAME monitor_over_socketcand
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/can/monitor_over_socketcand.py
                 $<TARGET_FILE:drive_hil> $<TARGET_FILE:drive_monitor> ${PROJECT_SOURCE_DIR}
                 ${CMAKE_CURRENT_BINARY_DIR}/monitor_over_socketcand)
set_tests_properties(monitor_over_socketcand PROPERTIES LABELS sim TIMEOUT 90)

# The processor-in-the-loop image compiles in scenarios written by scenario_embed: each
# committed source must be what the tool writes from its scenario file today.
foreach(embedded seed000_realistic:kSeed000Realistic seed001_realistic:kSeed001Realistic
                 seed000_realistic_20kHz:kSeed000Realistic20kHz)
  string(REPLACE ":" ";" parts ${embedded})
  list(GET parts 0 name)
  list(GET parts 1 symbol)
  add_test(NAME scenario_embed_up_to_date_${name}
           COMMAND ${CMAKE_COMMAND} -E env
                   sh -c "\"$1\" \"$2\" --name ${name} --symbol ${symbol} --output \"$3\" && ${CMAKE_COMMAND} -E compare_files \"$3\" \"$4\" || { echo \"$4 is out of date: regenerate it with scenario_embed (see its first line)\"; exit 1; }"
                   sh $<TARGET_FILE:scenario_embed>
                   ${PROJECT_SOURCE_DIR}/hal_sim/scenarios/${name}.toml
                   ${CMAKE_BINARY_DIR}/${name}_scenario.cpp
                   ${PROJECT_SOURCE_DIR}/firmware/cortex_m/pil/${name}_scenario.cpp)
  set_tests_properties(scenario_embed_up_to_date_${name} PROPERTIES LABELS unit)
endforeach()
