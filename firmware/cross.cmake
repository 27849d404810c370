# Cross builds of the firmware (arm-none-eabi-gcc), run with a plain custom
# command so the host's flags (sanitizers, -O levels) never leak into them.
#   cbvh-rp2040.elf    RP2040 + iCE40UP5K port (pico-ice, docs/board.md):
#                      boot2, freestanding, no libc; its flash/RAM use is
#                      printed and checked against a budget.
#   firmware_rp2040.uf2  that image plus the FPGA bitstream in its flash
#                      region, for drag-and-drop onto the RP2040's boot drive.
#   cbvh-selftest.elf  firmware core + model on mps2-an385 (Cortex-M3), run
#                      under qemu with semihosting; its reply digest must equal
#                      the host build's, and it must pass every golden vector
#                      of vectors/ (the model without unsigned __int128).
option(CBVH_FIRMWARE_CROSS "Cross-compile the firmware images when arm-none-eabi-gcc is found" ON)
find_program(CBVH_ARM_GCC arm-none-eabi-gcc)
find_program(CBVH_ARM_SIZE arm-none-eabi-size)
find_program(CBVH_QEMU_ARM qemu-system-arm)

set(fw_dir ${CMAKE_CURRENT_SOURCE_DIR})
set(model_dir ${PROJECT_SOURCE_DIR}/rtl-model)
# The datapath units (CBVH_MODEL_SOURCES, not the builders in rtl-model/src).
set(fw_model_sources ${CBVH_MODEL_SOURCES})

# Host build of the self-test: the reference digest.
add_executable(fw_selftest_host ports/qemu_mps2/selftest.c)
target_link_libraries(fw_selftest_host PRIVATE cbvh_fw_sim)

# Host tool that checksums boot2, wraps the bitstream and writes the UF2
# (ports/rp2040_ice40/tools/rp2040_image.c): built with the host compiler.
add_executable(rp2040_image ports/rp2040_ice40/tools/rp2040_image.c)
find_program(CBVH_ARM_OBJCOPY arm-none-eabi-objcopy)
set(CBVH_RP2040_UF2 "" CACHE INTERNAL "the RP2040 image (UF2), empty when not built")
set(CBVH_RP2040_BITSTREAM "" CACHE INTERNAL "the bitstream in the UF2, empty when none")

if(CBVH_ARM_GCC AND CBVH_ARM_SIZE AND CBVH_ARM_OBJCOPY AND CBVH_FIRMWARE_CROSS)
  set(warn -std=c11 -Wall -Wextra -Werror)
  set(p ${fw_dir}/ports/rp2040_ice40)
  set(m0 -mcpu=cortex-m0plus -mthumb)
  # boot2: linked at its SRAM address, checksummed into 256 bytes.
  set(boot2_elf ${CMAKE_CURRENT_BINARY_DIR}/rp2040_boot2.elf)
  set(boot2_bin ${CMAKE_CURRENT_BINARY_DIR}/rp2040_boot2.bin)
  add_custom_command(OUTPUT ${boot2_bin}
    COMMAND ${CBVH_ARM_GCC} ${m0} -Os ${warn} -ffreestanding -nostdlib -T${p}/boot2.ld ${p}/boot2.c -o ${boot2_elf}
    COMMAND ${CBVH_ARM_OBJCOPY} -O binary ${boot2_elf} ${boot2_bin}.raw
    COMMAND rp2040_image boot2 ${boot2_bin}.raw ${boot2_bin}
    DEPENDS ${p}/boot2.c ${p}/boot2.ld rp2040_image
    COMMENT "RP2040 boot2 (W25Q-style QSPI flash) with its CRC" VERBATIM)
  set(rp2040_sources ${CBVH_FW_CORE_SOURCES}
      ${p}/main.c ${p}/startup.c ${p}/clocks.c ${p}/fpga_config.c ${p}/spi_regmap.c
      ${p}/usbd.c ${p}/usb_desc.c ${p}/usb_link.c ${p}/usb_rp2040.c)
  set(rp2040_elf ${CMAKE_CURRENT_BINARY_DIR}/cbvh-rp2040.elf)
  add_custom_command(OUTPUT ${rp2040_elf}
    COMMAND ${CBVH_ARM_GCC} ${m0} -Os ${warn} -ffreestanding -nostdlib
            -ffunction-sections -fdata-sections -I${fw_dir}/include -I${p}
            ${rp2040_sources} -DBOOT2_BIN="${boot2_bin}" ${p}/boot2_blob.S
            -T${p}/rp2040.ld -Wl,--gc-sections -lgcc -o ${rp2040_elf}
    COMMAND ${CBVH_ARM_SIZE} ${rp2040_elf}
    DEPENDS ${rp2040_sources} ${p}/rp2040.ld ${p}/boot2_blob.S ${boot2_bin} ${p}/board.h ${p}/port.h
            ${p}/rp2040_regs.h ${p}/usbd.h ${p}/usb_link.h
    COMMENT "Cross-compiling the RP2040 firmware (arm-none-eabi-gcc, Cortex-M0+)" VERBATIM)

  # The FPGA bitstream (gateware/scripts/build-bitstream, default units, about
  # 30 s) in its named flash region (board.h BOARD_BITSTREAM_ADDR).
  find_program(CBVH_YOSYS_BIN yosys)
  find_program(CBVH_NEXTPNR nextpnr-ice40)
  find_program(CBVH_ICEPACK icepack)
  set(uf2 ${CMAKE_CURRENT_BINARY_DIR}/firmware_rp2040.uf2)
  set(fw_bin ${CMAKE_CURRENT_BINARY_DIR}/cbvh-rp2040.bin)
  set(uf2_parts 0x10000000 ${fw_bin})
  set(uf2_deps ${rp2040_elf})
  if(CBVH_YOSYS_BIN AND CBVH_NEXTPNR AND CBVH_ICEPACK)
    set(gw ${PROJECT_SOURCE_DIR}/gateware)
    file(GLOB bit_sources ${gw}/rtl/*.v ${gw}/board/*.v)
    set(bits ${CMAKE_CURRENT_BINARY_DIR}/cbvh_board.bin)
    add_custom_command(OUTPUT ${bits}
      COMMAND sh -c "bash '${gw}/scripts/build-bitstream' -w '${CMAKE_CURRENT_BINARY_DIR}/bitstream' -o '${bits}' \
> '${bits}.log' 2>&1 || { cat '${bits}.log'; exit 1; }"
      DEPENDS ${bit_sources} ${gw}/board/board.pcf ${gw}/scripts/build-bitstream
      COMMENT "Building the FPGA bitstream for the RP2040 image (gateware/scripts/build-bitstream)" VERBATIM)
    add_custom_command(OUTPUT ${bits}.region
      COMMAND rp2040_image bitstream ${bits} ${bits}.region
      DEPENDS ${bits} rp2040_image VERBATIM)
    list(APPEND uf2_parts 0x10100000 ${bits}.region)
    list(APPEND uf2_deps ${bits}.region)
    set(CBVH_RP2040_BITSTREAM ${bits} CACHE INTERNAL "")
  else()
    message(STATUS "RP2040 image without an FPGA bitstream (yosys, nextpnr-ice40, icepack not all found)")
  endif()
  add_custom_command(OUTPUT ${uf2}
    COMMAND ${CBVH_ARM_OBJCOPY} -O binary ${rp2040_elf} ${fw_bin}
    COMMAND rp2040_image uf2 ${uf2} ${uf2_parts}
    DEPENDS ${uf2_deps} rp2040_image
    COMMENT "firmware_rp2040.uf2 (firmware at 0x10000000, bitstream region at 0x10100000)" VERBATIM)
  add_custom_target(firmware_rp2040 ALL DEPENDS ${rp2040_elf} ${uf2})
  set(CBVH_RP2040_UF2 ${uf2} CACHE INTERNAL "")
  set(CBVH_RP2040_ELF ${rp2040_elf} CACHE INTERNAL "")

  set(selftest_sources ${CBVH_FW_CORE_SOURCES} ${fw_dir}/ports/sim/regmap_model.c ${fw_model_sources}
      ${fw_dir}/ports/qemu_mps2/selftest.c ${fw_dir}/ports/qemu_mps2/vectors.c)
  set(selftest_elf ${CMAKE_CURRENT_BINARY_DIR}/cbvh-selftest.elf)
  add_custom_command(OUTPUT ${selftest_elf}
    COMMAND ${CBVH_ARM_GCC} -mcpu=cortex-m3 -mthumb -O2 ${warn} -I${fw_dir}/include -I${fw_dir}/ports/sim
            -I${model_dir}/include -I${model_dir}/src ${selftest_sources} --specs=rdimon.specs
            -T${fw_dir}/ports/qemu_mps2/mps2.ld -o ${selftest_elf}
    DEPENDS ${selftest_sources} ${fw_dir}/ports/qemu_mps2/mps2.ld
    COMMENT "Cross-compiling the firmware self-test for mps2-an385 (Cortex-M3)" VERBATIM)
  # Not in ALL: the image needs the whole model to cross-compile, which is
  # checked (and reported) by the test itself, so a model that does not build
  # for a 32-bit target cannot break the host build.
  add_custom_target(firmware_selftest DEPENDS ${selftest_elf})

  # Flash/RAM budget of the RP2040 image (boot2 and firmware, not the
  # bitstream region): 64 KiB flash, 32 KiB RAM.
  add_test(NAME firmware_rp2040_size
           COMMAND sh ${fw_dir}/scripts/check_size.sh ${CBVH_ARM_SIZE} ${rp2040_elf} 65536 32768)
  if(CBVH_QEMU_ARM)
    add_test(NAME firmware_qemu_selftest
             COMMAND sh ${fw_dir}/scripts/run_qemu_selftest.sh ${CMAKE_BINARY_DIR} ${CBVH_QEMU_ARM} ${selftest_elf}
                     $<TARGET_FILE:fw_selftest_host> ${PROJECT_SOURCE_DIR}/vectors)
  else()
    add_test(NAME firmware_qemu_selftest
             COMMAND sh -c "echo 'SKIP: qemu-system-arm not installed (apt-get install qemu-system-arm)'; exit 77")
  endif()
else()
  foreach(t firmware_rp2040_size firmware_qemu_selftest)
    add_test(NAME ${t} COMMAND sh -c
             "echo 'SKIP: arm-none-eabi-gcc not installed (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi)'; exit 77")
  endforeach()
endif()
set_tests_properties(firmware_rp2040_size firmware_qemu_selftest PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 60)
