# The host CAN tools: candump -L logs (tools/can_log), SocketCAN (hal/linux) and drive_monitor.
# Test names contain can_log, socketcan or monitor; all are in the unit tier.
imd_add_test(test_can_log unit LIBRARIES imd_can_log
             SOURCES tools/test_can_log.cpp tools/test_can_log_kinds.cpp)
imd_add_test(test_drive_monitor unit LIBRARIES imd_drive_monitor SOURCES tools/test_drive_monitor.cpp)
imd_add_test(test_drive_monitor_repeat unit LIBRARIES imd_drive_monitor
             SOURCES tools/test_drive_monitor_repeat.cpp)
imd_add_test(test_drive_monitor_parameters unit LIBRARIES imd_drive_monitor
             SOURCES tools/test_drive_monitor_parameters.cpp)
imd_add_test(test_drive_monitor_capture unit LIBRARIES imd_drive_monitor
             SOURCES tools/test_drive_monitor_capture.cpp)
# send set-speed --enable against a drive on the simulated board.
imd_add_test(test_drive_monitor_enable sim LIBRARIES imd_drive_monitor imd_hal_sim
             SOURCES tools/test_drive_monitor_enable.cpp)
# drive_sim --can-log's two directions, on a short run of the CAN scenario.
imd_add_test(test_can_log_host_frames sim LIBRARIES imd_can_log imd_sim_drive
             SOURCES tools/test_can_log_host_frames.cpp)

# drive_monitor: exit code 2 and a clear message on bad input (the interface is checked on a
# machine that may have no CAN at all: either message is clear), decoding of a recorded log.
if(TARGET drive_monitor)
  set(CAN_DATA ${CMAKE_CURRENT_SOURCE_DIR}/data/can)
  set(NO_CAN_IFACE "drive_monitor: vcan9: (socket\\(PF_CAN\\): .*support in this kernel|no such CAN interface)")
  function(imd_monitor_test NAME CODE PATTERN)
    imd_tool_test(drive_monitor ${NAME} ${CODE} ${PATTERN} ${ARGN})
  endfunction()
  imd_monitor_test(drive_monitor_help 0 "watch" --help)
  imd_monitor_test(drive_monitor_no_subcommand 2 "A subcommand is required")
  imd_monitor_test(drive_monitor_no_source 2
                   "drive_monitor: watch: give --can IFACE, --socketcand HOST:PORT or --log FILE"
                   watch)
  imd_monitor_test(drive_monitor_send_no_bus 2
                   "drive_monitor: send: give --can IFACE or --socketcand HOST:PORT"
                   send --node 1 enable)
  imd_monitor_test(drive_monitor_bad_socketcand_address 2
                   "drive_monitor: --socketcand host:0: expected PORT, HOST:PORT or \\[V6\\]:PORT with a port in 1..65535"
                   parameters --socketcand host:0 --node 1)
  imd_monitor_test(drive_monitor_can_and_socketcand 2 "--can excludes --socketcand"
                   identify --can vcan0 --socketcand 127.0.0.1:29536 --node 1)
  imd_monitor_test(drive_monitor_bad_interface 2 "${NO_CAN_IFACE}" watch --can vcan9)
  imd_monitor_test(drive_monitor_send_bad_interface 2 "${NO_CAN_IFACE}"
                   send --can vcan9 --node 1 enable)
  imd_monitor_test(drive_monitor_long_interface_name 2 "interface name longer than 15 characters"
                   watch --can interface_name_17)
  imd_monitor_test(drive_monitor_missing_log 2 "drive_monitor: /nonexistent.log: cannot open file"
                   watch --log /nonexistent.log)
  imd_monitor_test(drive_monitor_bad_log_line 2
                   "drive_monitor: .*/bad_line.log:3: data '0801000' has an odd number of hex digits"
                   watch --log ${CAN_DATA}/bad_line.log)
  imd_monitor_test(drive_monitor_extended_id 0
                   "2 frames: 1 decoded .*skipped: 0 error frames, 1 with 29-bit ids,"
                   watch --log ${CAN_DATA}/extended_id.log)
  # A capture of a shared bus (candump -L -x): node 1's frames decode as from a clean log, the
  # rest is counted; shared_bus.log holds monitor_sample.log's frames and the others. ('.' in
  # the patterns stands for ';', which CMake would take for a list separator.)
  imd_monitor_test(drive_monitor_shared_bus 0
                   "47 frames: 30 decoded \\(26 from node 1, 4 commands to it\\). skipped: 3 error frames, 3 with 29-bit ids, 2 CAN FD, 2 remote, 6 of other nodes \\(node 2: 6\\), 1 of unknown messages, 0 of wrong length. the capture lost 2 frames"
                   watch --log ${CAN_DATA}/shared_bus.log)
  imd_monitor_test(drive_monitor_shared_bus_csv 0
                   "^1700000000\\.130300,37\\.02,100\\.00,0\\.8099,0\\.8100,4\\.50,-2\\.25,0\\.50,301\\.7,30\\.3,-20\\.2,1\\.0000,3,running,none$"
                   watch --log ${CAN_DATA}/shared_bus.log --csv - --no-table)
  imd_monitor_test(drive_monitor_other_node_only 4
                   "warning: no frame from node 1 on .*node2_only.log. heard only other nodes \\(node 2: 7\\): is --node right\\?"
                   watch --log ${CAN_DATA}/node2_only.log --no-table)
  imd_monitor_test(drive_monitor_other_node_watched 0 "8 frames: 7 decoded \\(6 from node 2, 1 commands to it\\)"
                   watch --log ${CAN_DATA}/node2_only.log --node 2 --no-table)
  imd_monitor_test(drive_monitor_bad_dropcount_line 2
                   "drive_monitor: .*/bad_dropcount.log:2: bad DROPCOUNT line 'DROPCOUNT: dropped 2 CAN frames on can0 socket"
                   watch --log ${CAN_DATA}/bad_dropcount.log)
  imd_monitor_test(drive_monitor_bad_fd_line 2
                   "drive_monitor: .*/bad_fd_line.log:2: CAN FD data '00112233445566778899' has 10 bytes"
                   watch --log ${CAN_DATA}/bad_fd_line.log)
  imd_monitor_test(drive_monitor_log_table 0
                   "last ack +set_speed counter 3: accepted, rejected_total 1"
                   watch --log ${CAN_DATA}/monitor_sample.log)
  imd_monitor_test(drive_monitor_log_csv 0
                   "^0\\.130300,37\\.02,100\\.00,0\\.8099,0\\.8100,4\\.50,-2\\.25,0\\.50,301\\.7,30\\.3,-20\\.2,1\\.0000,3,running,none$"
                   watch --log ${CAN_DATA}/monitor_sample.log --csv - --no-table)
  imd_monitor_test(drive_monitor_log_duration 0 "samples +1 rows"
                   watch --log ${CAN_DATA}/monitor_sample.log --duration-s 0.12)
  imd_monitor_test(drive_monitor_bad_duration 2 "duration-s: must be a time in \\(0, 1e7\\] s, got -1"
                   watch --log ${CAN_DATA}/monitor_sample.log --duration-s -1)
  imd_monitor_test(drive_monitor_bad_node 2 "--node: Value 64 not in range 0 to 63"
                   watch --log ${CAN_DATA}/monitor_sample.log --node 64)
  imd_monitor_test(drive_monitor_send_not_a_number 2 "drive_monitor: set-speed: 'fast' is not a number"
                   send --can vcan9 --node 1 set-speed fast)
  imd_monitor_test(drive_monitor_send_unrepresentable 2 "set-speed: 3e6 cannot be represented"
                   send --can vcan9 --node 1 set-speed 3e6)
  imd_monitor_test(drive_monitor_send_unknown_controller 2
                   "unknown controller 'pid' \\(known: dsmc, iol, ifoc\\)"
                   send --can vcan9 --node 1 select-controller pid)
  imd_monitor_test(drive_monitor_send_bad_rate 2 "set-telemetry-rate: 5 must be a whole number of Hz"
                   send --can vcan9 --node 1 set-telemetry-rate 5)
  imd_monitor_test(drive_monitor_send_unknown_command 2 "unknown command 'reboot'"
                   send --can vcan9 --node 1 reboot)
  imd_monitor_test(drive_monitor_send_missing_value 2 "set-speed needs a value \\(RAD_S\\)"
                   send --can vcan9 --node 1 set-speed)
  imd_monitor_test(drive_monitor_parameters_unknown_key 2
                   "'Rx_Ohm' is not a motor parameter \\(known: Rs_Ohm, Ls_H"
                   parameters --can vcan9 --node 1 --set Rx_Ohm=1)
  imd_monitor_test(drive_monitor_parameters_not_a_number 2 "Rr_Ohm: 'hot' is not a finite number"
                   parameters --can vcan9 --node 1 --set Rr_Ohm=hot)
  imd_monitor_test(drive_monitor_parameters_bad_motor_file 2
                   "bad_negative_Rs.toml: motor.Rs_Ohm = -1: must be > 0"
                   parameters --can vcan9 --node 1
                   --motor-file ${CMAKE_CURRENT_SOURCE_DIR}/data/motors/bad_negative_Rs.toml)
  imd_monitor_test(drive_monitor_parameters_bad_interface 2 "${NO_CAN_IFACE}"
                   parameters --can vcan9 --node 1)
  imd_monitor_test(drive_monitor_send_bad_counter 2 "--counter: Value 16 not in range 0 to 15"
                   send --can vcan9 --node 1 --counter 16 enable)
  # A CSV that cannot be created is bad input, found before the log is read: exit 2, as the
  # help says.
  imd_monitor_test(drive_monitor_csv_not_creatable 2
                   "drive_monitor: /nonexistent/t.csv: cannot open file for writing"
                   watch --log ${CAN_DATA}/monitor_sample.log --csv /nonexistent/t.csv)
  imd_monitor_test(drive_monitor_watch_help_exit_codes 0
                   "2 bad input \\(command line, interface, a CSV that cannot be created"
                   watch --help)
  # send --enable: only with set-speed, and only repeated (the watchdog needs the repeats).
  imd_monitor_test(drive_monitor_send_enable_needs_repeat 2 "--enable requires --repeat-hz"
                   send --can vcan9 --node 1 set-speed 30 --enable)
  imd_monitor_test(drive_monitor_send_enable_with_set_speed_only 2
                   "drive_monitor: --enable goes with set-speed only .*, not set-flux"
                   send --can vcan9 --node 1 set-flux 0.2 --repeat-hz 10 --for-s 1 --enable)
endif()

# libFuzzer harnesses (clang only): the fuzz preset turns them on.
if(IMD_BUILD_FUZZERS)
  add_subdirectory(fuzz)
endif()
