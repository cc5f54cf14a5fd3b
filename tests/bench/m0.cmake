# The Cortex-M0 benchmark images of tools/bench (tools/m0count.py counts
# their instructions under qemu-system-arm): tests/bench/bench.c, one image
# per operation, each linked with the stack and its product family built
# as that product's MCU image is (boards/CMakeLists.txt: the product's fixed
# node config and table sizes from od/<family>/family.cmake, no object names,
# no simulated faults; -Os, LTO, Thumb-1 from cmake/arm-none-eabi.cmake;
# boards/common/libc_min.c and aeabi_div.c), started and ended like the
# qemu unit tests (co_bare_io: startup.c, semihosting). Included by
# tests/qemu/CMakeLists.txt after co_bare_io.
# Also the counter's own check (m0_counter.c, ctest bench.m0_counter).

# Operations per image: the count is an average over them, as on x86.
set(CO_BENCH_N 1000)
# "name number config [calls]": the products of the x86 rows (bench.c);
# calls, where given, replaces CO_BENCH_N (a save is 20 000 to 50 000
# instructions: 100 of them average as well and trace in seconds, not a
# minute; tools/bench's M0_CALLS says the same).
set(CO_BENCH_OPS
  "sdo-expedited 1 dst_x730_cfg"
  "sdo-segment 2 pf_iny_cfg"
  "tpdo 3 dst_x730_cfg"
  "idle-poll 4 dst_x730_cfg"
  "sync 5 jd2_cfg"
  "save 6 dst_x730_cfg 100"
  "save-jd 7 jd2_cfg 100")
set(CO_BENCH_DIR ${PROJECT_SOURCE_DIR}/tests/bench)
add_custom_target(bench_m0 ALL)
foreach(entry ${CO_BENCH_OPS})
  separate_arguments(f UNIX_COMMAND "${entry}")
  list(GET f 0 op)
  list(GET f 1 num)
  list(GET f 2 cfg)
  set(calls ${CO_BENCH_N})
  list(LENGTH f nf)
  if(nf GREATER 3)
    list(GET f 3 calls)
  endif()
  set(lib co_bench_fw_${cfg})
  if(NOT TARGET ${lib})
    # The family of the config, as its declaration names it (od/<family>/family.cmake).
    set(fam)
    foreach(c ${CO_MCU_FIXED_CFGS})
      separate_arguments(cf UNIX_COMMAND "${c}")
      list(GET cf 0 c0)
      if(c0 STREQUAL cfg)
        list(GET cf 1 fam)
      endif()
    endforeach()
    add_library(${lib} STATIC ${CO_STACK_SOURCES} ${PROJECT_SOURCE_DIR}/od/bitrates.c
      ${CO_FAMILY_SOURCES_${fam}})
    target_include_directories(${lib} PUBLIC ${PROJECT_SOURCE_DIR}/include ${CO_PRODUCT_INCLUDES})
    target_compile_options(${lib} PRIVATE ${CO_BARE_FLAGS})
    target_compile_definitions(${lib} PUBLIC CO_OD_NO_NAMES CO_NO_SIM_INPUT
      CO_FIXED_CFG=${cfg} ${CO_MCU_SIZES_${cfg}})
  endif()
  add_executable(bench_m0_${op} ${CO_BENCH_DIR}/bench.c)
  set_target_properties(bench_m0_${op} PROPERTIES SUFFIX ".elf")
  target_compile_definitions(bench_m0_${op} PRIVATE BENCH_BARE=${num} BENCH_N=${calls})
  target_compile_options(bench_m0_${op} PRIVATE ${CO_BARE_FLAGS})
  target_link_libraries(bench_m0_${op} PRIVATE ${lib} co_bare_io gcc)
  target_link_options(bench_m0_${op} PRIVATE -T${QEMU_DIR}/link.ld -Wl,--fatal-warnings)
  add_dependencies(bench_m0 bench_m0_${op})
endforeach()

add_executable(m0_counter ${CO_BENCH_DIR}/m0_counter.c)
set_target_properties(m0_counter PROPERTIES SUFFIX ".elf")
target_compile_options(m0_counter PRIVATE ${CO_BARE_FLAGS})
target_link_libraries(m0_counter PRIVATE co_bare_io gcc)
target_link_options(m0_counter PRIVATE -T${QEMU_DIR}/link.ld -Wl,--fatal-warnings)
add_dependencies(bench_m0 m0_counter)
