# Pepperl+Fuchs INX360D (one axis) and INY360D (two axes) inclinometers
# (shared/specs/pf-inx-iny.md).
co_family(pf
  HEADER pf.h
  INSTANCE pf_dev_t
  SOURCES pf.c pf_inx_iny.c
  TESTS test_pf_manual
  PRODUCTS
    # ID     product symbol  MCU image's fixed config
    inx360d  pf_inx360d      pf_inx_cfg
    iny360d  pf_iny360d      pf_iny_cfg)
