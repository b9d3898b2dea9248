# Firmware images for Cortex-M4F targets.
#
# imd_add_cortex_m_image(NAME LINKER_SCRIPT script [TICK_ROOTS sym...] [NO_DOUBLE]
#                        [FLASH_BUDGET bytes] [RAM_BUDGET bytes]
#                        [STACK_LEVELS handlers...] SOURCES src... LIBRARIES lib...)
# links NAME.elf with the target's linker script (which asserts the budgets, when it has them)
# and writes NAME.map, NAME.size.txt, and the
# flashable NAME.bin (raw, from the first flash address) and NAME.hex (Intel HEX). The
# link itself refuses exceptions: every throw entry point is wrapped (--wrap) and the wrappers
# are never defined, so a reference fails with "undefined reference to `__wrap___cxa_throw'".
# operator new is never defined either. The C allocator is wrapped to traps (there is no heap,
# hal/cortex_m/no_heap.cpp says why it is named at all). With TICK_ROOTS,
# tools/check_tick_path.py then follows the static call graph from those interrupt entries and
# fails the build if the tick can reach double-precision soft-float, the allocator (or its
# traps) or exceptions; with NO_DOUBLE, also if double-precision soft-float is linked at all.
# With STACK_LEVELS (the interrupt levels that preempt the main loop, lowest first, each a
# comma-separated list of handlers), tools/check_stack.py bounds the stack from the compiler's
# frames and the call graph, fails the build if the bound exceeds the linker script's
# STACK_SIZE and writes the deepest paths to NAME.stack.txt.
find_package(Python3 REQUIRED COMPONENTS Interpreter)

# Each object's call graph with its functions' frames (NAME.ci beside the object) and its
# final GIMPLE (NAME.*.optimized: which indirect calls are virtual), from which
# tools/check_stack.py bounds the stack of an image (imd_add_cortex_m_image's STACK_LEVELS).
add_compile_options(-fcallgraph-info=su -fdump-tree-optimized)

set(IMD_NO_HEAP_NO_EXCEPTIONS_WRAPS
    malloc free calloc realloc memalign _malloc_r _free_r _calloc_r _realloc_r _memalign_r
    __cxa_allocate_exception __cxa_throw __cxa_rethrow __cxa_begin_catch _Unwind_Resume
    _Unwind_RaiseException)

find_program(IMD_ARM_SIZE arm-none-eabi-size REQUIRED)
find_program(IMD_ARM_OBJCOPY arm-none-eabi-objcopy REQUIRED)

function(imd_add_cortex_m_image NAME)
  cmake_parse_arguments(ARG "NO_DOUBLE" "LINKER_SCRIPT;FLASH_BUDGET;RAM_BUDGET"
                        "TICK_ROOTS;STACK_LEVELS;SOURCES;LIBRARIES" ${ARGN})
  add_executable(${NAME} ${ARG_SOURCES})
  set_target_properties(${NAME} PROPERTIES SUFFIX ".elf")
  target_link_libraries(${NAME} PRIVATE ${ARG_LIBRARIES} imd_hal_cortex_m imd_cortex_m_runtime)
  get_filename_component(script_dir ${ARG_LINKER_SCRIPT} DIRECTORY)
  set(wraps "")
  foreach(symbol IN LISTS IMD_NO_HEAP_NO_EXCEPTIONS_WRAPS)
    list(APPEND wraps "LINKER:--wrap=${symbol}")
  endforeach()
  target_link_options(${NAME} PRIVATE -nostartfiles -T ${ARG_LINKER_SCRIPT} -L ${script_dir}
                      "LINKER:-Map=$<TARGET_FILE_DIR:${NAME}>/${NAME}.map"
                      ${wraps})
  set_property(TARGET ${NAME} APPEND PROPERTY LINK_DEPENDS ${ARG_LINKER_SCRIPT})
  # Budgets below the chip's regions, which the linker script asserts (bytes).
  if(ARG_FLASH_BUDGET)
    target_link_options(${NAME} PRIVATE "LINKER:--defsym=IMD_FLASH_BUDGET=${ARG_FLASH_BUDGET}")
  endif()
  if(ARG_RAM_BUDGET)
    target_link_options(${NAME} PRIVATE "LINKER:--defsym=IMD_RAM_BUDGET=${ARG_RAM_BUDGET}")
  endif()
  add_custom_command(TARGET ${NAME} POST_BUILD
    COMMAND ${IMD_ARM_SIZE} $<TARGET_FILE:${NAME}> > $<TARGET_FILE_DIR:${NAME}>/${NAME}.size.txt
    VERBATIM)
  # The images a programmer takes, and a check that both hold the same bytes: the HEX read back
  # as raw binary must equal the .bin (objcopy fills gaps alike in both).
  set(base $<TARGET_FILE_DIR:${NAME}>/${NAME})
  add_custom_command(TARGET ${NAME} POST_BUILD
    COMMAND ${IMD_ARM_OBJCOPY} -O binary $<TARGET_FILE:${NAME}> ${base}.bin
    COMMAND ${IMD_ARM_OBJCOPY} -O ihex $<TARGET_FILE:${NAME}> ${base}.hex
    COMMAND ${IMD_ARM_OBJCOPY} -I ihex -O binary ${base}.hex ${base}.hex.bin
    COMMAND ${CMAKE_COMMAND} -E compare_files ${base}.bin ${base}.hex.bin
    COMMAND ${CMAKE_COMMAND} -E remove ${base}.hex.bin
    BYPRODUCTS ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/${NAME}.bin
               ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/${NAME}.hex
    VERBATIM)
  if(ARG_TICK_ROOTS)
    set(roots "")
    foreach(root IN LISTS ARG_TICK_ROOTS)
      list(APPEND roots --root ${root})
    endforeach()
    if(ARG_NO_DOUBLE)
      list(APPEND roots --no-double-in-image)
    endif()
    add_custom_command(TARGET ${NAME} POST_BUILD
      COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/check_tick_path.py
              --objdump ${CMAKE_OBJDUMP} $<TARGET_FILE:${NAME}> ${roots}
              --deny-regex "^__wrap_"
              --report $<TARGET_FILE_DIR:${NAME}>/${NAME}.tick_path.txt
      VERBATIM)
  endif()
  if(ARG_STACK_LEVELS)
    set(levels "")
    foreach(level IN LISTS ARG_STACK_LEVELS)
      list(APPEND levels --level ${level})
    endforeach()
    add_custom_command(TARGET ${NAME} POST_BUILD
      COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/check_stack.py
              --objdump ${CMAKE_OBJDUMP} $<TARGET_FILE:${NAME}>
              --map $<TARGET_FILE_DIR:${NAME}>/${NAME}.map --build-dir ${PROJECT_BINARY_DIR}
              ${levels} --report $<TARGET_FILE_DIR:${NAME}>/${NAME}.stack.txt
      VERBATIM)
  endif()
endfunction()

# imd_add_flash_target(NAME IMAGE): `cmake --build --preset cortex-m4f --target NAME` programs
# IMAGE's ELF into an STM32G4 over an ST-LINK with openocd, verifies it and resets the chip
# (cmake/Flash.cmake; docs/flashing.md). openocd is looked for when flashing, not when
# configuring, so installing it later needs no reconfiguration.
set(IMD_OPENOCD_INTERFACE "interface/stlink.cfg" CACHE STRING
    "openocd interface script of the flashing probe (docs/flashing.md)")
set(IMD_OPENOCD_TARGET "target/stm32g4x.cfg" CACHE STRING "openocd target script of the MCU")
function(imd_add_flash_target NAME IMAGE)
  add_custom_target(${NAME}
    COMMAND ${CMAKE_COMMAND} -DIMAGE=$<TARGET_FILE:${IMAGE}>
            -DINTERFACE=${IMD_OPENOCD_INTERFACE} -DTARGET=${IMD_OPENOCD_TARGET}
            -P ${PROJECT_SOURCE_DIR}/cmake/Flash.cmake
    DEPENDS ${IMAGE}
    USES_TERMINAL
    COMMENT "Flashing ${IMAGE} with openocd (${IMD_OPENOCD_INTERFACE}, ${IMD_OPENOCD_TARGET})"
    VERBATIM)
endfunction()

# imd_optimize_for_size(DIRECTORY dir SOURCES src...): compile these sources of the library in
# dir with -Os on the MCU: code that runs in the main loop (the model build, the laws' designs,
# the parameter record) or only while commissioning, never in a running drive's tick, which
# stays -O2 (docs/performance-image.md, "Flash and RAM of the board image").
function(imd_optimize_for_size)
  cmake_parse_arguments(ARG "" "DIRECTORY" "SOURCES" ${ARGN})
  list(TRANSFORM ARG_SOURCES PREPEND ${ARG_DIRECTORY}/)  # relative paths would name this dir's
  set_source_files_properties(${ARG_SOURCES} DIRECTORY ${ARG_DIRECTORY}
                              PROPERTIES COMPILE_OPTIONS "-Os")
endfunction()
