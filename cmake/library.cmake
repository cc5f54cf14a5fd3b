# The stack and its products as libraries that a product outside this tree
# links (docs/library.md), in the tree (add_subdirectory) and installed
# (cmake --install: headers, static libraries, the CMake package
# canopen_sensors, the pkg-config file canopen_sensors.pc).
#
#   canopen::stack          src/ (include/): the portable stack
#   canopen::product        od/bitrates.c, od/product.h: what a product is
#   host only:
#   canopen::family_<name>  each shipped family of od/ (its header, sources)
#   canopen::registry       od/registry.c: product_list, product_find over
#                           the shipped products
#   canopen::linux_port     boards/linux/{can_port,nvm_file,log}.c: the
#                           stack's port on SocketCAN, an EEPROM file, a log
#   cross builds only (the toolchain file's CO_BOARD):
#   canopen::board_<board>  boards/<board> and boards/common's pieces it needs
#   canopen::mcu_main       boards/common/mcu_main.c as a source the consumer
#                           compiles with its PRODUCT_SYM, PRODUCT_HEADER,
#                           PRODUCT_INST_SIZE; the board's link script
#
# The firmware images (boards/CMakeLists.txt), the Linux program and the
# tests build their own libraries and are not changed by these.

if(CMAKE_CROSSCOMPILING AND NOT DEFINED CMAKE_INSTALL_LIBDIR)
  # A bare-metal target has no multiarch folder (and GNUInstallDirs, not
  # knowing the pointer size there, would warn): plain lib.
  set(CMAKE_INSTALL_LIBDIR lib CACHE PATH "Object code libraries (lib)")
endif()
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CO_PKG canopen_sensors)
set(CO_INSTALL_INCLUDEDIR ${CMAKE_INSTALL_INCLUDEDIR}/canopen)
set(CO_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/${CO_PKG})
set(CO_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/${CO_PKG})

# What the stack is built with, and passes on to everything compiled
# against it: the size switches (co_tpdo.h, co_sdo.h, co_emcy.h, co_incl.h)
# and CO_FIXED_CFG=<config symbol> (co_node.h), which change the node's
# layout and code, so the stack, the product's dictionary and the board
# code must agree on them.
set(CO_STACK_DEFINITIONS "" CACHE STRING
  "Size switches and CO_FIXED_CFG for canopen::stack, e.g. CO_TPDO_MAX=1u;CO_SDO_BUF=4u")
foreach(def ${CO_STACK_DEFINITIONS})
  string(REGEX REPLACE "=.*" "" switch "${def}")
  if(NOT switch IN_LIST CO_SIZE_SWITCHES AND NOT switch STREQUAL "CO_FIXED_CFG")
    message(FATAL_ERROR "CO_STACK_DEFINITIONS: ${def}: not a size switch (${CO_SIZE_SWITCHES}) "
      "nor CO_FIXED_CFG")
  endif()
endforeach()

set(co_lib_flags ${CO_WARNINGS})
if(CMAKE_CROSSCOMPILING)
  list(APPEND co_lib_flags -ffreestanding -fno-builtin)
endif()
set(co_lib_targets)
set(co_debug_postfix d) # a Debug build's names: its libraries and its .pc file

# A library of this tree: its output name libcanopen_<export>.a, its
# exported name canopen::<export>.
function(co_library target export)
  add_library(${target} STATIC ${ARGN})
  add_library(canopen::${export} ALIAS ${target})
  # A Debug build's libraries are libcanopen_<export>d.a: Debug and
  # Release installs share a prefix.
  set_target_properties(${target} PROPERTIES OUTPUT_NAME canopen_${export} EXPORT_NAME ${export}
    DEBUG_POSTFIX ${co_debug_postfix})
  # In a parent project (add_subdirectory) a library is built when the
  # parent links it, not with the parent's "all".
  if(NOT CO_TOP_LEVEL)
    set_target_properties(${target} PROPERTIES EXCLUDE_FROM_ALL TRUE)
  endif()
  target_compile_options(${target} PRIVATE ${co_lib_flags})
  target_compile_features(${target} PUBLIC c_std_11)
  set(co_lib_targets ${co_lib_targets} ${target} PARENT_SCOPE)
endfunction()

# ---- the stack and what a product is ------------------------------------
co_library(co_stack stack ${CO_STACK_SOURCES})
target_include_directories(co_stack PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<INSTALL_INTERFACE:${CO_INSTALL_INCLUDEDIR}>)
target_compile_definitions(co_stack PUBLIC ${CO_STACK_DEFINITIONS})
set(co_pc_cflags)
foreach(def ${CO_STACK_DEFINITIONS})
  string(APPEND co_pc_cflags " -D${def}")
endforeach()
if(CMAKE_CROSSCOMPILING)
  # No object names in flash: an MCU prints no EDS (co_od.h, CO_NAME).
  target_compile_definitions(co_stack PUBLIC CO_OD_NO_NAMES)
  string(APPEND co_pc_cflags " -DCO_OD_NO_NAMES")
endif()

co_library(co_product product ${PROJECT_SOURCE_DIR}/od/bitrates.c)
target_include_directories(co_product PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/od>
  $<INSTALL_INTERFACE:${CO_INSTALL_INCLUDEDIR}>)
target_link_libraries(co_product PUBLIC co_stack)
set(co_headers ${PROJECT_SOURCE_DIR}/od/product.h ${PROJECT_SOURCE_DIR}/od/product_eds.h)
file(GLOB co_stack_headers ${PROJECT_SOURCE_DIR}/include/*.h)
list(APPEND co_headers ${co_stack_headers})

if(NOT CMAKE_CROSSCOMPILING)
  # ---- the shipped families and their registry (host) -------------------
  set(co_family_targets)
  foreach(fam ${CO_FAMILIES})
    if(CO_FAMILY_EXAMPLE_${fam})
      continue() # a template: copied, not linked
    endif()
    co_library(co_family_${fam} family_${fam} ${CO_FAMILY_SOURCES_${fam}})
    target_include_directories(co_family_${fam} PUBLIC
      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/od/${fam}> $<INSTALL_INTERFACE:${CO_INSTALL_INCLUDEDIR}>)
    target_link_libraries(co_family_${fam} PUBLIC co_product)
    list(APPEND co_headers ${PROJECT_SOURCE_DIR}/od/${fam}/${CO_FAMILY_HEADER_${fam}})
    list(APPEND co_family_targets co_family_${fam})
  endforeach()
  # product_list and product_find (product.h) over the shipped products.
  # The generated header it is built from (cmake/families.cmake) names
  # every family, the templates too: private, not installed.
  co_library(co_registry registry ${PROJECT_SOURCE_DIR}/od/registry.c)
  target_include_directories(co_registry PRIVATE ${PROJECT_BINARY_DIR}/generated)
  foreach(fam ${CO_FAMILIES})
    if(CO_FAMILY_EXAMPLE_${fam})
      target_include_directories(co_registry PRIVATE ${PROJECT_SOURCE_DIR}/od/${fam})
    endif()
  endforeach()
  target_link_libraries(co_registry PUBLIC ${co_family_targets})

  # ---- the Linux port (host) ---------------------------------------------
  set(co_linux ${PROJECT_SOURCE_DIR}/boards/linux)
  co_library(co_linux_port linux_port ${co_linux}/can_port.c ${co_linux}/nvm_file.c
    ${co_linux}/log.c)
  target_compile_definitions(co_linux_port PRIVATE _GNU_SOURCE)
  # Its headers in a folder of their own: log.h is too common a name.
  target_include_directories(co_linux_port PUBLIC $<BUILD_INTERFACE:${co_linux}>
    $<INSTALL_INTERFACE:${CO_INSTALL_INCLUDEDIR}/linux>)
  target_link_libraries(co_linux_port PUBLIC co_stack)
  # The stack calls back into the port (co_port.h), and a consumer's link
  # line has the port's archive before the stack's: one that calls no lp_*
  # function itself left can_port.o unread when the archive came by, and
  # co_port_* undefined after the stack. Marked undefined from the start
  # (each function co_port.h declares), they are taken from this archive
  # whatever the order.
  file(STRINGS ${PROJECT_SOURCE_DIR}/include/co_port.h co_port_decls
    REGEX "^[a-z].*[ *]co_port_[a-z0-9_]+\\(")
  set(co_port_undefined)
  foreach(decl ${co_port_decls})
    string(REGEX MATCH "co_port_[a-z0-9_]+" fn "${decl}")
    list(APPEND co_port_undefined "LINKER:--undefined=${fn}")
  endforeach()
  if(NOT co_port_undefined)
    message(FATAL_ERROR "include/co_port.h: no co_port_* function found for canopen::linux_port")
  endif()
  target_link_options(co_linux_port INTERFACE ${co_port_undefined})
  set(co_linux_headers ${co_linux}/can_port.h ${co_linux}/nvm_file.h ${co_linux}/log.h)
else()
  # ---- the board of the toolchain file (cross) ---------------------------
  # As boards/CMakeLists.txt builds it for the images.
  set(co_bdir ${PROJECT_SOURCE_DIR}/boards/${CO_BOARD})
  set(co_cdir ${PROJECT_SOURCE_DIR}/boards/common)
  string(REPLACE "-" "_" co_bname ${CO_BOARD})
  # boot_ident.c: the application's side of the hand-over to the board's
  # bootloader (boot.h), which mcu_main.c calls after each pass.
  set(co_bsrc ${co_bdir}/board.c ${co_cdir}/libc_min.c ${co_cdir}/boot_ident.c)
  set_source_files_properties(${co_cdir}/libc_min.c ${co_cdir}/aeabi_div.c PROPERTIES
    COMPILE_OPTIONS -fno-lto) # called behind LTO's back (boards/CMakeLists.txt)
  set(co_sim_input OFF)
  if(CO_BOARD STREQUAL "nucleo-f042k6" OR CO_BOARD STREQUAL "microbit")
    list(APPEND co_bsrc ${co_bdir}/startup.c ${co_cdir}/aeabi_div.c ${co_cdir}/flash_ee.c)
  endif()
  if(CO_BOARD STREQUAL "rv32-virt" OR CO_BOARD STREQUAL "microbit")
    list(APPEND co_bsrc ${co_cdir}/serial_link.c)
    set(co_sim_input ON)
  endif()
  if(CO_BOARD STREQUAL "rv32-virt")
    list(APPEND co_bsrc ${co_bdir}/cfi_flash.c ${co_cdir}/flash_ee.c ${co_cdir}/sja1000.c)
  endif()
  if(NOT co_sim_input)
    # Real hardware has no simulated input: no fault names (product.h).
    target_compile_definitions(co_product PUBLIC CO_NO_SIM_INPUT)
    string(APPEND co_pc_cflags " -DCO_NO_SIM_INPUT")
  endif()
  co_library(co_board_${co_bname} board_${co_bname} ${co_bsrc})
  target_include_directories(co_board_${co_bname} PUBLIC $<BUILD_INTERFACE:${co_cdir}>
    $<INSTALL_INTERFACE:${CO_INSTALL_INCLUDEDIR}>)
  target_include_directories(co_board_${co_bname} PRIVATE ${co_bdir})
  target_link_libraries(co_board_${co_bname} PUBLIC co_product)
  if(CO_BOARD STREQUAL "rv32-virt")
    target_compile_definitions(co_board_${co_bname} PUBLIC BOARD_RX_FILTER)
  endif()
  list(APPEND co_headers ${co_cdir}/board.h ${co_cdir}/boot.h ${co_cdir}/flash_ee.h)

  # The main loop as a source of the consumer's image: it names the
  # product (PRODUCT_SYM ...), so the consumer compiles it. Board and
  # stack twice: they call each other (the port functions).
  add_library(co_mcu_main INTERFACE)
  add_library(canopen::mcu_main ALIAS co_mcu_main)
  set_target_properties(co_mcu_main PROPERTIES EXPORT_NAME mcu_main)
  target_sources(co_mcu_main INTERFACE $<BUILD_INTERFACE:${co_cdir}/mcu_main.c>
    $<INSTALL_INTERFACE:${CO_INSTALL_DATADIR}/mcu_main.c>)
  target_compile_options(co_mcu_main INTERFACE -ffreestanding -fno-builtin)
  target_link_libraries(co_mcu_main INTERFACE co_board_${co_bname} co_stack co_board_${co_bname}
    co_stack gcc)
  target_link_options(co_mcu_main INTERFACE
    -L$<BUILD_INTERFACE:${co_bdir}>$<INSTALL_INTERFACE:$<INSTALL_PREFIX>/${CO_INSTALL_DATADIR}>
    -T$<BUILD_INTERFACE:${co_bdir}/link.ld>$<INSTALL_INTERFACE:$<INSTALL_PREFIX>/${CO_INSTALL_DATADIR}/link.ld>)
  list(APPEND co_lib_targets co_mcu_main)
endif()

if(NOT CO_INSTALL)
  return()
endif()

# ---- installation ----------------------------------------------------------
install(TARGETS ${co_lib_targets} EXPORT ${CO_PKG}Targets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES ${co_headers} DESTINATION ${CO_INSTALL_INCLUDEDIR})
if(NOT CMAKE_CROSSCOMPILING)
  install(FILES ${co_linux_headers} DESTINATION ${CO_INSTALL_INCLUDEDIR}/linux)
else()
  # link.ld includes layout.ld (the flash layout it shares with the
  # bootloader's): found through the -L above.
  install(FILES ${co_cdir}/mcu_main.c ${co_bdir}/link.ld ${co_bdir}/layout.ld
    DESTINATION ${CO_INSTALL_DATADIR})
  # The toolchain files (the one this was built with includes others): a
  # consumer builds with the same.
  install(FILES ${PROJECT_SOURCE_DIR}/cmake/arm-none-eabi.cmake
    ${PROJECT_SOURCE_DIR}/cmake/microbit.cmake ${PROJECT_SOURCE_DIR}/cmake/riscv32.cmake
    DESTINATION ${CO_INSTALL_DATADIR})
endif()
install(EXPORT ${CO_PKG}Targets NAMESPACE canopen:: DESTINATION ${CO_INSTALL_CMAKEDIR})

# The package: its version file refuses a consumer built for another
# system or processor (a host project does not take a Cortex-M0 one).
file(WRITE ${PROJECT_BINARY_DIR}/${CO_PKG}Config.cmake.in [=[
@PACKAGE_INIT@
# canopen_sensors @PROJECT_VERSION@, built for @CMAKE_SYSTEM_NAME@ @CMAKE_SYSTEM_PROCESSOR@
# (board: @CO_BOARD@); docs/library.md of the source tree.
set(canopen_sensors_BOARD "@CO_BOARD@")
set(canopen_sensors_STACK_DEFINITIONS "@CO_STACK_DEFINITIONS@")
include("${CMAKE_CURRENT_LIST_DIR}/canopen_sensorsTargets.cmake")
check_required_components(canopen_sensors)
]=])
configure_package_config_file(${PROJECT_BINARY_DIR}/${CO_PKG}Config.cmake.in
  ${PROJECT_BINARY_DIR}/${CO_PKG}Config.cmake INSTALL_DESTINATION ${CO_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/${CO_PKG}ConfigVersionBasic.cmake
  COMPATIBILITY SameMinorVersion)
# The basic file's pointer-size check misses a cross build (no size there).
file(WRITE ${PROJECT_BINARY_DIR}/${CO_PKG}ConfigVersion.cmake.in [=[
include("${CMAKE_CURRENT_LIST_DIR}/canopen_sensorsConfigVersionBasic.cmake")
if(NOT "${CMAKE_SYSTEM_NAME} ${CMAKE_SYSTEM_PROCESSOR}" STREQUAL "@CMAKE_SYSTEM_NAME@ @CMAKE_SYSTEM_PROCESSOR@")
  set(PACKAGE_VERSION "${PACKAGE_VERSION} (for @CMAKE_SYSTEM_NAME@ @CMAKE_SYSTEM_PROCESSOR@)")
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
# One Cortex-M0 is not another: a consumer whose toolchain file names a
# board (CO_BOARD) takes that board's package only.
if(DEFINED CO_BOARD AND NOT "@CO_BOARD@" STREQUAL "" AND NOT CO_BOARD STREQUAL "@CO_BOARD@")
  set(PACKAGE_VERSION "${PACKAGE_VERSION} (for the board @CO_BOARD@)")
  set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
]=])
configure_file(${PROJECT_BINARY_DIR}/${CO_PKG}ConfigVersion.cmake.in
  ${PROJECT_BINARY_DIR}/${CO_PKG}ConfigVersion.cmake @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/${CO_PKG}Config.cmake
  ${PROJECT_BINARY_DIR}/${CO_PKG}ConfigVersion.cmake
  ${PROJECT_BINARY_DIR}/${CO_PKG}ConfigVersionBasic.cmake DESTINATION ${CO_INSTALL_CMAKEDIR})

# pkg-config: the stack (canopen::stack) and what a product is
# (canopen::product), with the definitions they were built with, and the
# libraries by their names in this configuration: a Debug build's are
# libcanopen_<name>d.a (DEBUG_POSTFIX), and its .pc file is
# canopen_sensorsd.pc, so that a Debug and a Release install in one prefix
# each keep theirs (the Release one is canopen_sensors.pc).
file(WRITE ${PROJECT_BINARY_DIR}/${CO_PKG}.pc.in [=[
prefix=${pcfiledir}/@co_pc_up@
includedir=${prefix}/@CMAKE_INSTALL_INCLUDEDIR@/canopen
libdir=${prefix}/@CMAKE_INSTALL_LIBDIR@

Name: canopen_sensors$<$<CONFIG:Debug>: (Debug)>
Description: Portable CANopen slave stack (C11, no heap): the stack and product.h
Version: @PROJECT_VERSION@
Cflags: -I${includedir}@co_pc_cflags@
Libs: -L${libdir} -l$<TARGET_FILE_BASE_NAME:co_product> -l$<TARGET_FILE_BASE_NAME:co_stack>
]=])
# Relocatable (the prefix from the .pc file's place) unless the library
# directory was given as an absolute path.
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  message(FATAL_ERROR "CMAKE_INSTALL_LIBDIR=${CMAKE_INSTALL_LIBDIR}: give it relative to "
    "CMAKE_INSTALL_PREFIX (the package and its .pc file find their files from their place)")
endif()
file(RELATIVE_PATH co_pc_up /root/${CMAKE_INSTALL_LIBDIR}/pkgconfig /root)
configure_file(${PROJECT_BINARY_DIR}/${CO_PKG}.pc.in ${PROJECT_BINARY_DIR}/${CO_PKG}.pc.gen @ONLY)
# One file per configuration (a multi-config generator has several).
set(co_pc_file "${PROJECT_BINARY_DIR}/pkgconfig-$<CONFIG>/${CO_PKG}$<$<CONFIG:Debug>:${co_debug_postfix}>.pc")
file(GENERATE OUTPUT ${co_pc_file} INPUT ${PROJECT_BINARY_DIR}/${CO_PKG}.pc.gen)
install(FILES ${co_pc_file} DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
