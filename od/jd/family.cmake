# ifm JD1xxx (one axis) and JD2xxx (two axes) inclinometers
# (after their operating instructions).
co_family(jd
  HEADER jd.h
  INSTANCE jd_dev_t
  SOURCES jd.c jd_tables.c
  TESTS test_jd_manual test_jd_edge
  PRODUCTS
    # ID    product symbol  MCU image's fixed config
    jd1xxx  jd1xxx          jd1_cfg
    jd2xxx  jd2xxx          jd2_cfg)
