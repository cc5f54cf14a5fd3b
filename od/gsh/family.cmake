# Gefran GSH-A draw-wire + tilt sensor, single and redundant (two nodes in
# one device), after the Gefran "CANopen GSH-A" manual (Cod. 80782).
co_family(gsh
  HEADER gsh.h
  INSTANCE gsh_dev_t
  SOURCES gsh.c gsh_a.c
  TESTS test_gsh_manual
  PRODUCTS
    # ID             product symbol   MCU image's fixed config ("-": two nodes, two configs)
    gsh-a            gsh_a            gsh_ch1_cfg
    gsh-a-redundant  gsh_a_redundant  -)
