# The unit tests that also run on the emulated Cortex-M0 (all but the Linux
# board's, and test_board_common: there libc_min.c is linked for real and
# mcu_main.c is an image's own main): read by tests/qemu/CMakeLists.txt (to
# build them) and by tests/CMakeLists.txt (to run them under qemu-system-arm).
set(CO_BARE_TESTS ${CO_UNIT_FAMILY_TESTS}
  test_stack test_store test_profile test_hardening test_flash_ee test_div
  test_sdo_edge test_store_faults test_node_services test_products_edge
  test_serial_link)
