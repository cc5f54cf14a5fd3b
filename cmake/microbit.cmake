# Cortex-M0 (nRF51822, BBC micro:bit; qemu-system-arm -M microbit), bare
# metal, -Os: the arm toolchain settings of the Nucleo's file, another board.
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi.cmake)
set(CO_BOARD microbit CACHE STRING "MCU board" FORCE)
