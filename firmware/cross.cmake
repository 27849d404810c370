# Cross builds of the firmware (arm-none-eabi-gcc), run with a plain custom
# command so the host's flags (sanitizers, -O levels) never leak into them.
#   cbvh-rp2040.elf    RP2040 + iCE40UP5K port: freestanding, no libc; its
#                      flash/RAM use is printed and checked against a budget.
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

if(CBVH_ARM_GCC AND CBVH_ARM_SIZE AND CBVH_FIRMWARE_CROSS)
  set(warn -std=c11 -Wall -Wextra -Werror)
  set(rp2040_sources ${CBVH_FW_CORE_SOURCES}
      ${fw_dir}/ports/rp2040_ice40/main.c ${fw_dir}/ports/rp2040_ice40/spi_regmap.c
      ${fw_dir}/ports/rp2040_ice40/usb_link.c ${fw_dir}/ports/rp2040_ice40/startup.c)
  set(rp2040_elf ${CMAKE_CURRENT_BINARY_DIR}/cbvh-rp2040.elf)
  add_custom_command(OUTPUT ${rp2040_elf}
    COMMAND ${CBVH_ARM_GCC} -mcpu=cortex-m0plus -mthumb -Os ${warn} -ffreestanding -nostdlib
            -ffunction-sections -fdata-sections -I${fw_dir}/include -I${fw_dir}/ports/rp2040_ice40
            ${rp2040_sources} -T${fw_dir}/ports/rp2040_ice40/rp2040.ld -Wl,--gc-sections -lgcc -o ${rp2040_elf}
    COMMAND ${CBVH_ARM_SIZE} ${rp2040_elf}
    DEPENDS ${rp2040_sources} ${fw_dir}/ports/rp2040_ice40/rp2040.ld
    COMMENT "Cross-compiling the RP2040 firmware (arm-none-eabi-gcc, Cortex-M0+)" VERBATIM)
  add_custom_target(firmware_rp2040 ALL DEPENDS ${rp2040_elf})

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

  # Flash/RAM budget of the RP2040 image: 64 KiB flash, 32 KiB RAM.
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
