# The product families: each folder od/<family>/ declares itself once, in
# od/<family>/family.cmake, with co_family() below. Everything else reads
# what the declarations set: the root build (the stack library, the Linux
# program's product registry), boards/CMakeLists.txt (one MCU image per
# product), tests/ (each family's unit tests, once per fixed config, on the
# host and on the emulated Cortex-M0), tests/bench, and through the Linux
# program's `--list-products --json` tools/emu, tools/demo.py and the
# integration tests.
#
# co_family(<name>
#   HEADER   <file.h>         the family's header (declares the products)
#   INSTANCE <type>           the instance type a product's create() builds
#   SOURCES  <file.c>...      relative to the family's folder
#   TESTS    <test>...        tests/unit/<test>.c, run by every fixed config
#   PRODUCTS <id> <symbol> <config>...
#                             one row per product: its ID, its product_t
#                             symbol, the node config its MCU image fixes at
#                             build time (CO_FIXED_CFG, co_node.h) or "-"
#                             when it has more than one (the two nodes of
#                             the redundant GSH-A)
#   [SIZES <config> <DEFINE=value>...]
#                             table sizes below the stack's defaults for
#                             the images of one config (co_tpdo.h, co_sdo.h,
#                             co_emcy.h, co_incl.h); one SIZES per config
#   [EXAMPLE])                a template (od/skeleton): built and tested,
#                             but not in the Linux program's product list
#                             and no MCU image
#
# Sets, in the including scope:
#   CO_FAMILIES                 family names, in od/ folder order
#   CO_FAMILY_SOURCES_<name>    absolute source paths
#   CO_FAMILY_HEADER_<name>, CO_FAMILY_TESTS_<name>
#   CO_FAMILY_EXAMPLE_<name>    true for a template (EXAMPLE)
#   CO_PRODUCT_SOURCES          every family's sources and od/'s shared ones
#   CO_PRODUCT_INCLUDES         od/, every family folder, the generated header
#   CO_UNIT_FAMILY_TESTS        every family's tests
#   CO_MCU_PRODUCTS             "id symbol family instance config" rows
#   CO_MCU_FIXED_CFGS           "config family" rows, each config once
#   CO_MCU_SIZES_<config>       the SIZES of that config
# and writes <build>/generated/product_registry.h (the registry's rows,
# od/registry.c; each product's family, MCU config and template flag,
# boards/linux/products_json.c; the union of the instance types, product.h).

set(CO_FAMILIES)
set(CO_PRODUCT_SOURCES ${PROJECT_SOURCE_DIR}/od/bitrates.c ${PROJECT_SOURCE_DIR}/od/registry.c)
set(CO_PRODUCT_INCLUDES ${PROJECT_SOURCE_DIR}/od ${PROJECT_BINARY_DIR}/generated)
set(CO_UNIT_FAMILY_TESTS)
set(CO_MCU_PRODUCTS)
set(CO_MCU_FIXED_CFGS)
set(co_registry_includes "")
set(co_registry_rows "")
set(co_registry_info "")
set(co_registry_examples "")
set(co_registry_union "")
set(co_registry_ids "")
set(co_registry_example_ids "")
set(co_all_ids)
set(co_all_syms)
# The size switches a family's SIZES may set (each range-checked by #error
# next to its default in include/).
set(CO_SIZE_SWITCHES CO_TPDO_MAX CO_SDO_BUF CO_EMCY_HIST_MAX CO_EMCY_ACTIVE_MAX CO_INCL_CIRCULAR)

macro(co_family name)
  cmake_parse_arguments(fam "EXAMPLE" "HEADER;INSTANCE" "SOURCES;TESTS;PRODUCTS;SIZES" ${ARGN})
  set(fam_dir ${PROJECT_SOURCE_DIR}/od/${name})
  if(NOT "${name}" STREQUAL "${co_family_folder}")
    message(FATAL_ERROR "od/${co_family_folder}/family.cmake: co_family(${name} ...) must be named "
      "like its folder: co_family(${co_family_folder} ...)")
  endif()
  foreach(req HEADER INSTANCE SOURCES TESTS PRODUCTS)
    if(NOT fam_${req})
      message(FATAL_ERROR "od/${name}/family.cmake: co_family() needs ${req}")
    endif()
  endforeach()
  if(fam_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "od/${name}/family.cmake: unknown words: ${fam_UNPARSED_ARGUMENTS}")
  endif()
  foreach(src ${fam_SOURCES} ${fam_HEADER})
    if(NOT EXISTS ${fam_dir}/${src})
      message(FATAL_ERROR "od/${name}/family.cmake: od/${name}/${src} does not exist "
        "(a misspelt keyword is read as a source: HEADER INSTANCE SOURCES TESTS PRODUCTS SIZES EXAMPLE)")
    endif()
  endforeach()
  foreach(t ${fam_TESTS})
    if(NOT EXISTS ${PROJECT_SOURCE_DIR}/tests/unit/${t}.c)
      message(FATAL_ERROR "od/${name}/family.cmake: TESTS names ${t}, but tests/unit/${t}.c does not exist")
    endif()
  endforeach()
  list(APPEND CO_FAMILIES ${name})
  set(CO_FAMILY_EXAMPLE_${name} ${fam_EXAMPLE})
  list(TRANSFORM fam_SOURCES PREPEND ${fam_dir}/ OUTPUT_VARIABLE CO_FAMILY_SOURCES_${name})
  set(CO_FAMILY_HEADER_${name} ${fam_HEADER})
  set(CO_FAMILY_TESTS_${name} ${fam_TESTS})
  list(APPEND CO_PRODUCT_SOURCES ${CO_FAMILY_SOURCES_${name}})
  list(APPEND CO_PRODUCT_INCLUDES ${fam_dir})
  list(APPEND CO_UNIT_FAMILY_TESTS ${fam_TESTS})
  string(APPEND co_registry_includes "#include \"${fam_HEADER}\"\n")
  string(APPEND co_registry_union "    ${fam_INSTANCE} ${name};\n")
  list(LENGTH fam_PRODUCTS n)
  math(EXPR rem "${n} % 3")
  if(NOT rem EQUAL 0)
    message(FATAL_ERROR "od/${name}/family.cmake: PRODUCTS takes rows of three: ID symbol config")
  endif()
  math(EXPR last "${n} - 1")
  set(fam_cfgs)
  foreach(i RANGE 0 ${last} 3)
    math(EXPR i1 "${i} + 1")
    math(EXPR i2 "${i} + 2")
    list(GET fam_PRODUCTS ${i} id)
    list(GET fam_PRODUCTS ${i1} sym)
    list(GET fam_PRODUCTS ${i2} cfg)
    if(NOT id MATCHES "^[a-z0-9-]+$" OR NOT sym MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
      message(FATAL_ERROR "od/${name}/family.cmake: bad product row: ${id} ${sym} ${cfg}")
    endif()
    if(id IN_LIST co_all_ids)
      message(FATAL_ERROR "od/${name}/family.cmake: product ID ${id} is declared twice")
    endif()
    if(sym IN_LIST co_all_syms)
      message(FATAL_ERROR "od/${name}/family.cmake: product symbol ${sym} is declared twice")
    endif()
    list(APPEND co_all_ids ${id})
    list(APPEND co_all_syms ${sym})
    list(APPEND fam_cfgs ${cfg})
    set(info_cfg "\"${cfg}\"")
    if(cfg STREQUAL "-")
      set(info_cfg NULL)
    endif()
    set(info_example false)
    if(fam_EXAMPLE)
      set(info_example true)
      string(APPEND co_registry_examples "&${sym}, ")
      string(APPEND co_registry_example_ids "\"${id}\", ")
    else()
      string(APPEND co_registry_rows "&${sym}, ")
      string(APPEND co_registry_ids "\"${id}\", ")
      list(APPEND CO_MCU_PRODUCTS "${id} ${sym} ${name} ${fam_INSTANCE} ${cfg}")
    endif()
    string(APPEND co_registry_info "    {.id = \"${id}\", .family = \"${name}\", "
      ".mcu_cfg = ${info_cfg}, .example = ${info_example}}, \\\n")
    if(NOT cfg STREQUAL "-" AND NOT "${cfg} ${name}" IN_LIST CO_MCU_FIXED_CFGS)
      list(APPEND CO_MCU_FIXED_CFGS "${cfg} ${name}")
    endif()
  endforeach()
  # SIZES: <config> followed by its defines, repeated.
  set(cfg "")
  foreach(word ${fam_SIZES})
    if(word MATCHES "=")
      if(cfg STREQUAL "")
        message(FATAL_ERROR "od/${name}/family.cmake: SIZES must start with a config name")
      endif()
      string(REGEX REPLACE "=.*" "" switch "${word}")
      if(NOT switch IN_LIST CO_SIZE_SWITCHES)
        message(FATAL_ERROR "od/${name}/family.cmake: SIZES ${cfg}: ${switch} is no size switch "
          "(one of: ${CO_SIZE_SWITCHES})")
      endif()
      list(APPEND CO_MCU_SIZES_${cfg} ${word})
    else()
      if(NOT word IN_LIST fam_cfgs)
        message(FATAL_ERROR "od/${name}/family.cmake: SIZES names config ${word}, which no "
          "PRODUCTS row of the family uses")
      endif()
      set(cfg ${word})
      set(CO_MCU_SIZES_${cfg})
    endif()
  endforeach()
endmacro()

file(GLOB co_family_files LIST_DIRECTORIES false CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/od/*/family.cmake)
list(SORT co_family_files)
foreach(f ${co_family_files})
  get_filename_component(co_family_folder ${f} DIRECTORY)
  get_filename_component(co_family_folder ${co_family_folder} NAME)
  list(LENGTH CO_FAMILIES co_before)
  include(${f})
  list(LENGTH CO_FAMILIES co_after)
  math(EXPR co_want "${co_before} + 1")
  if(NOT co_after EQUAL co_want)
    message(FATAL_ERROR "od/${co_family_folder}/family.cmake must declare its family once: co_family(${co_family_folder} ...)")
  endif()
endforeach()

file(CONFIGURE OUTPUT ${PROJECT_BINARY_DIR}/generated/product_registry.h CONTENT
"/* Generated by cmake/families.cmake from the families' declarations
 * (od/<family>/family.cmake): do not edit. */
#ifndef PRODUCT_REGISTRY_H
#define PRODUCT_REGISTRY_H

#include <stdbool.h>
@co_registry_includes@
/* The products of the Linux program (--list-products order). */
#define PRODUCT_REGISTRY_ROWS @co_registry_rows@
/* Templates (EXAMPLE families): built and tested, not shipped. */
#define PRODUCT_REGISTRY_EXAMPLES @co_registry_examples@
/* The IDs the declarations give the rows above, in the same order (a
 * unit test checks each product's own id against its row). */
#define PRODUCT_REGISTRY_IDS @co_registry_ids@
#define PRODUCT_REGISTRY_EXAMPLE_IDS @co_registry_example_ids@
/* What a declaration says of a product besides its row (for
 * --list-products --json). */
typedef struct product_registry_info {
    const char *id;      /* its ID */
    const char *family;  /* its family (the folder under od/) */
    const char *mcu_cfg; /* the node config its MCU image fixes; NULL: none (two nodes) */
    bool example;        /* a template (EXAMPLE): no MCU image, not in the program's list */
} product_registry_info_t;
/* That of every product, templates too, in declaration order. */
#define PRODUCT_REGISTRY_INFO \\
@co_registry_info@
/* Every instance type, for memory that holds any product (product.h). */
typedef union product_any {
@co_registry_union@} product_any_t;

#endif /* PRODUCT_REGISTRY_H */
" @ONLY)
