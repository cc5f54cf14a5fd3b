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
# CO_M0_SIZE_OPT: -Os passes that cost flash on Thumb-1, whose 8 low
# registers make every value kept live across a loop or a branch a spill
# (measured on the DST X730 Nucleo image: smaller, and the instruction
# counts of tools/bench fall or stay): hoisting loop invariants
# and common code out of loops and branches (-fno-move-loop-invariants,
# -fno-tree-loop-im, -fno-code-hoisting; -fira-loop-pressure lets the
# allocator weigh that pressure), aggregates split into scalars that then
# live in registers (-fno-tree-sra), statements forwarded into their uses
# and branches turned into conditional moves, which Thumb-1 lacks
# (-fno-tree-forwprop, -fno-ssa-phiopt), and case tables (the small
# switches here are shorter as compares than as a table with libgcc's
# __gnu_thumb1_case_uqi). -fno-tree-ccp and -fno-tree-tail-merge: a few
# bytes each on the same image, which keep it within its 10 KB target. Not
# -fno-inline-functions-called-once: smaller, but the idle poll then takes
# more instructions than its target.
# Given as directory options, not in the cached CMAKE_C_FLAGS: a build
# directory configured before gets them at its next configure too.
set(CO_M0_SIZE_OPT "-fno-move-loop-invariants -fno-tree-loop-im -fno-code-hoisting -fira-loop-pressure -fno-tree-sra -fno-tree-forwprop -fno-ssa-phiopt -fno-jump-tables -fno-tree-ccp -fno-tree-tail-merge")
separate_arguments(CO_M0_SIZE_OPT_LIST UNIX_COMMAND "${CO_M0_SIZE_OPT}")
add_compile_options(${CO_M0_SIZE_OPT_LIST})
add_link_options(${CO_M0_SIZE_OPT_LIST})
set(CO_MCU_OPT "-Os -flto -fmerge-all-constants -fno-early-inlining -g")
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m0 -mthumb ${CO_MCU_OPT} -ffunction-sections -fdata-sections")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-mcpu=cortex-m0 -mthumb ${CO_MCU_OPT} -nostdlib -Wl,--gc-sections")
set(CO_BOARD nucleo-f042k6 CACHE STRING "MCU board")
