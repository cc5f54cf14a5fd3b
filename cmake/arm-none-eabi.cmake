# Cortex-M0 (STM32F042K6, Nucleo-F042K6), bare metal, -Os.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
# Link-time optimisation: about 6 % less flash (boards/common/libc_min.c is
# built without it, as the compiler's own memcpy/memset calls need it whole).
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m0 -mthumb -Os -flto -g -ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-mcpu=cortex-m0 -mthumb -Os -flto -g -nostdlib -Wl,--gc-sections")
set(CO_BOARD nucleo-f042k6 CACHE STRING "MCU board")
