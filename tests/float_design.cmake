# The float-design build (the float-design preset, IMD_DESIGN_IN_FLOAT): the drive's stages,
# laws, protections and commissioning, closed loop on every test motor, with the designs in
# float as the MCU computes them (control/real.hpp). The processor-in-the-loop image runs them
# too, on two motors and under QEMU; this tier covers the four motors, the sweeps and the fault
# matrix on the host. A test that checks an exactness only double designs reach skips itself
# here (tests/float_design_skip.hpp), saying why. Tools and benchmarks are not built.
imd_add_test(test_motor_parameters unit LIBRARIES imd_control tomlplusplus::tomlplusplus
             SOURCES control/test_motor_parameters.cpp)
imd_add_test(test_duration_ticks unit LIBRARIES imd_firmware SOURCES firmware/test_duration_ticks.cpp)
foreach(name test_drive_tick test_drive_commands test_dead_time test_drive_parameters
             test_drive_identification test_heartbeat_brake)
  imd_add_test(${name} unit LIBRARIES imd_firmware imd_hal_sim SOURCES firmware/${name}.cpp)
endforeach()
foreach(name test_standstill_identification test_inertia_identification)
  imd_add_test(${name} sim LIBRARIES imd_firmware imd_hal_sim SOURCES firmware/${name}.cpp)
endforeach()
foreach(name test_protection test_supervisor test_protection_checks test_adc_stuck_check
             test_limitation test_stop_category test_sense_stage test_protocol test_binary64)
  imd_add_test(${name} unit LIBRARIES imd_firmware SOURCES firmware/${name}.cpp)
endforeach()
imd_add_test(test_motor_record unit LIBRARIES imd_firmware tomlplusplus::tomlplusplus
             SOURCES firmware/test_motor_record.cpp)
imd_add_test(test_estimate_stage unit LIBRARIES imd_firmware tomlplusplus::tomlplusplus
             SOURCES firmware/test_estimate_stage.cpp)
target_compile_options(test_estimate_stage PRIVATE -ffp-contract=off)  # bit-for-bit (the test)
foreach(name test_voltage_fed_scenarios test_current_fed_scenarios test_rotor_resistance_tracking
             test_dsmc_torque_channel test_fault_matrix test_field_weakening test_phase_loss_sweep
             test_iol_voltage_limit_sweep test_stop_categories test_fault_recovery
             test_encoder_check_sweep test_adc_stuck_sweep test_commissioning_scenarios
             test_magnetizing_sweep test_lockstep_agreement test_random_healthy_sweep
             test_drive_at_20kHz)
  imd_add_test(${name} sim LIBRARIES imd_sim_drive SOURCES hal_sim/${name}.cpp)
endforeach()

set(IMD_FLOAT_DESIGN_TESTS
    test_motor_parameters test_duration_ticks
    test_drive_tick test_drive_commands test_dead_time test_drive_parameters
    test_drive_identification test_heartbeat_brake test_standstill_identification
    test_inertia_identification test_protection test_supervisor test_protection_checks
    test_adc_stuck_check test_limitation test_stop_category test_sense_stage test_protocol test_binary64
    test_motor_record test_estimate_stage test_voltage_fed_scenarios test_current_fed_scenarios
    test_rotor_resistance_tracking test_dsmc_torque_channel test_fault_matrix
    test_field_weakening test_phase_loss_sweep test_iol_voltage_limit_sweep test_stop_categories
    test_fault_recovery test_encoder_check_sweep test_adc_stuck_sweep test_commissioning_scenarios
    test_magnetizing_sweep test_lockstep_agreement test_drive_at_20kHz test_random_healthy_sweep)
add_custom_target(float_design_tests DEPENDS ${IMD_FLOAT_DESIGN_TESTS})
