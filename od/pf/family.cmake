# Pepperl+Fuchs INX360D (one axis) and INY360D (two axes) inclinometers
# (after the INX360D/INY360D-F99-B16-V15 manual).
co_family(pf
  HEADER pf.h
  INSTANCE pf_dev_t
  SOURCES pf.c pf_inx_iny.c
  TESTS test_pf_manual
  PRODUCTS
    # ID     product symbol  MCU image's fixed config
    inx360d  pf_inx360d      pf_inx_cfg
    iny360d  pf_iny360d      pf_iny_cfg)
