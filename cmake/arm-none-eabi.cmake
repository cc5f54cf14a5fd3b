# Cortex-M0 (STM32F042K6, Nucleo-F042K6), bare metal, -Os.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
# Link-time optimisation: about 11 % less flash (boards/common/libc_min.c and
# aeabi_div.c are built without it: the compiler calls them behind its back).
# -fmerge-all-constants: equal constants stored once (dictionary limits and
# hooks that repeat); the firmware never compares addresses of distinct
# constants. -fno-early-inlining: inlining decided once, for the whole image
# (about 1 % less flash here).
set(CO_MCU_OPT "-Os -flto -fmerge-all-constants -fno-early-inlining -g")
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m0 -mthumb ${CO_MCU_OPT} -ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-mcpu=cortex-m0 -mthumb ${CO_MCU_OPT} -nostdlib -Wl,--gc-sections")
set(CO_BOARD nucleo-f042k6 CACHE STRING "MCU board")
