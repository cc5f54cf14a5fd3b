# The template family: a one-axis CiA 410 inclinometer with the least a
# product needs (identity, heartbeat, one TPDO, the store, one fault). Not a
# real device (EXAMPLE): built into the unit tests' registry, tested on the
# host and on the emulated Cortex-M0 with its fixed config and table sizes,
# never in the Linux program's product list nor an MCU image. To start a
# family: copy this folder to od/<name>/, rename, drop EXAMPLE, and read
# README.md "Adding a product".
co_family(skeleton
  EXAMPLE
  HEADER skeleton.h
  INSTANCE skel_dev_t
  SOURCES skeleton.c
  TESTS test_skeleton
  PRODUCTS
    # ID           product symbol  MCU image's fixed config
    skeleton-incl  skel_incl       skel_cfg
  # One TPDO, no 0x1003 history, expedited SDO only: what the table uses.
  SIZES
    skel_cfg CO_TPDO_MAX=1u CO_EMCY_HIST_MAX=0u CO_EMCY_ACTIVE_MAX=1u CO_SDO_BUF=4u CO_INCL_CIRCULAR=0)
