# 32-bit RISC-V (rv32imac), QEMU "virt", bare metal, -Os.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR riscv32)
set(CMAKE_C_COMPILER riscv64-unknown-elf-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
# Debian's riscv64-unknown-elf-gcc ships no C headers; the stack needs only
# <string.h>'s declarations, taken from picolibc (no picolibc code is linked).
# Optimisation flags as on the Cortex-M0 (cmake/arm-none-eabi.cmake).
set(CO_MCU_OPT "-Os -flto -fmerge-all-constants -fno-early-inlining -g")
set(CMAKE_C_FLAGS_INIT "-march=rv32imac -mabi=ilp32 -mcmodel=medany ${CO_MCU_OPT} -ffunction-sections -fdata-sections -isystem /usr/lib/picolibc/riscv64-unknown-elf/include")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-march=rv32imac -mabi=ilp32 -mcmodel=medany ${CO_MCU_OPT} -nostdlib -Wl,--gc-sections")
set(CO_BOARD rv32-virt CACHE STRING "MCU board")
