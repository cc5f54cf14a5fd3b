# The MCU images' products, read by boards/CMakeLists.txt (one image per
# product and board) and by tests/CMakeLists.txt and tests/qemu (each fixed
# node config with its table sizes runs its family's unit tests, on the host
# and on the emulated Cortex-M0: a config mistake fails CI, not a device).

# ID, product symbol, family header, instance type, node config fixed at
# build time (CO_FIXED_CFG, co_node.h; "-": more than one, e.g. the two
# nodes of the redundant GSH-A).
set(CO_MCU_PRODUCTS
  "dst-x730-xy10 dst_x730_xy10 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-xy15 dst_x730_xy15 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-xy20 dst_x730_xy20 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-xy30 dst_x730_xy30 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-xy45 dst_x730_xy45 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-xy60 dst_x730_xy60 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-xy90 dst_x730_xy90 dst.h dst_dev_t dst_x730_cfg"
  "dst-x730-z360 dst_x730_z360 dst.h dst_dev_t dst_x730_cfg"
  "dst-x710-xy10 dst_x710_xy10 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-xy15 dst_x710_xy15 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-xy20 dst_x710_xy20 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-xy30 dst_x710_xy30 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-xy45 dst_x710_xy45 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-xy60 dst_x710_xy60 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-xy90 dst_x710_xy90 dst.h dst_dev_t dst_x710_cfg"
  "dst-x710-z360 dst_x710_z360 dst.h dst_dev_t dst_x710_cfg"
  "gsh-a gsh_a gsh.h gsh_dev_t gsh_ch1_cfg"
  "gsh-a-redundant gsh_a_redundant gsh.h gsh_dev_t -"
  "jd1xxx jd1xxx jd.h jd_dev_t jd1_cfg"
  "jd2xxx jd2xxx jd.h jd_dev_t jd2_cfg"
  "inx360d pf_inx360d pf.h pf_dev_t pf_inx_cfg"
  "iny360d pf_iny360d pf.h pf_dev_t pf_iny_cfg")

# Table sizes of the stack (co_tpdo.h, co_sdo.h, co_emcy.h) an image of
# one config needs, where they are below the defaults. The DSTs: TPDO1
# only, expedited SDO only (no transfer buffer), no 0x1003 history.
# No circular slope outputs either (co_incl.h).
set(CO_MCU_SIZES_dst_x730_cfg CO_TPDO_MAX=1u CO_SDO_BUF=4u CO_EMCY_HIST_MAX=0u CO_EMCY_ACTIVE_MAX=1u
  CO_INCL_CIRCULAR=0)
set(CO_MCU_SIZES_dst_x710_cfg ${CO_MCU_SIZES_dst_x730_cfg})

# Each family's sources, by its header (the third column above).
set(CO_FAMILY_dst.h od/dst.c od/dst_x730.c od/dst_x710.c)
set(CO_FAMILY_pf.h od/pf.c od/pf_inx_iny.c)
set(CO_FAMILY_gsh.h od/gsh.c od/gsh_a.c)
set(CO_FAMILY_jd.h od/jd.c od/jd_tables.c)

# Each family's unit tests, by its header: run by every fixed config of the
# family (a test that boots a product of another config ends there, "n/a").
set(CO_FAMILY_TESTS_dst.h test_dst_manual)
set(CO_FAMILY_TESTS_pf.h test_pf_manual)
set(CO_FAMILY_TESTS_gsh.h test_gsh_manual)
set(CO_FAMILY_TESTS_jd.h test_jd_manual test_jd_edge)

# The fixed configs (not "-"), each once, with its family header:
# CO_MCU_FIXED_CFGS = "cfg header" entries.
set(CO_MCU_FIXED_CFGS)
foreach(entry ${CO_MCU_PRODUCTS})
  separate_arguments(f UNIX_COMMAND "${entry}")
  list(GET f 2 header)
  list(GET f 4 cfg)
  if(NOT cfg STREQUAL "-" AND NOT "${cfg} ${header}" IN_LIST CO_MCU_FIXED_CFGS)
    list(APPEND CO_MCU_FIXED_CFGS "${cfg} ${header}")
  endif()
endforeach()
