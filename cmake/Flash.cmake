# cmake -P script (cmake/CortexM.cmake, imd_add_flash_target): programs IMAGE (an ELF) with
# openocd through INTERFACE and TARGET (openocd scripts), verifies it and resets the chip.
# openocd's "program" erases only the flash pages the image covers, so the parameter record in
# the last two pages survives (docs/porting.md, "Motor parameters in flash").
find_program(OPENOCD openocd)
if(NOT OPENOCD)
  string(REGEX REPLACE "\\.elf$" ".bin" bin "${IMAGE}")
  message(FATAL_ERROR
    "openocd not found: install Debian's openocd (sudo apt-get install openocd), or flash the "
    "raw image with st-flash (Debian's stlink-tools): "
    "st-flash --reset write ${bin} 0x08000000 (docs/flashing.md)")
endif()
if(NOT EXISTS "${IMAGE}")
  message(FATAL_ERROR "${IMAGE}: no such image: build it first")
endif()
execute_process(
  COMMAND ${OPENOCD} -f ${INTERFACE} -f ${TARGET} -c "program {${IMAGE}} verify reset exit"
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR
    "openocd failed (${status}) flashing ${IMAGE}: is the probe plugged in (lsusb shows "
    "STMicroelectronics ST-LINK), the board powered, SWDIO/SWCLK/GND/NRST wired, and may this "
    "user open the probe (udev rules of Debian's openocd package, group plugdev)? "
    "docs/flashing.md")
endif()
