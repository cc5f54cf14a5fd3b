# Danfoss DST X730 (filtered) and DST X710 inclinometers, CiA 410
# (after the DST X730 and DST X710 operating guides).
co_family(dst
  HEADER dst.h
  INSTANCE dst_dev_t
  SOURCES dst.c dst_tables.c
  TESTS test_dst_manual
  PRODUCTS
    # ID             product symbol  MCU image's fixed config
    dst-x730-xy10    dst_x730_xy10   dst_x730_cfg
    dst-x730-xy15    dst_x730_xy15   dst_x730_cfg
    dst-x730-xy20    dst_x730_xy20   dst_x730_cfg
    dst-x730-xy30    dst_x730_xy30   dst_x730_cfg
    dst-x730-xy45    dst_x730_xy45   dst_x730_cfg
    dst-x730-xy60    dst_x730_xy60   dst_x730_cfg
    dst-x730-xy90    dst_x730_xy90   dst_x730_cfg
    dst-x730-z360    dst_x730_z360   dst_x730_cfg
    dst-x710-xy10    dst_x710_xy10   dst_x710_cfg
    dst-x710-xy15    dst_x710_xy15   dst_x710_cfg
    dst-x710-xy20    dst_x710_xy20   dst_x710_cfg
    dst-x710-xy30    dst_x710_xy30   dst_x710_cfg
    dst-x710-xy45    dst_x710_xy45   dst_x710_cfg
    dst-x710-xy60    dst_x710_xy60   dst_x710_cfg
    dst-x710-xy90    dst_x710_xy90   dst_x710_cfg
    dst-x710-z360    dst_x710_z360   dst_x710_cfg
  # TPDO1 only, expedited SDO only (no transfer buffer), no 0x1003 history,
  # no circular slope outputs.
  SIZES
    dst_x730_cfg CO_TPDO_MAX=1u CO_SDO_BUF=4u CO_EMCY_HIST_MAX=0u CO_EMCY_ACTIVE_MAX=1u CO_INCL_CIRCULAR=0
    dst_x710_cfg CO_TPDO_MAX=1u CO_SDO_BUF=4u CO_EMCY_HIST_MAX=0u CO_EMCY_ACTIVE_MAX=1u CO_INCL_CIRCULAR=0)
