# The unit tests that also run on the emulated Cortex-M0 (all but the Linux
# board's, and test_board_common: there libc_min.c is linked for real and
# mcu_main.c is an image's own main): read by tests/qemu/CMakeLists.txt (to
# build them) and by tests/CMakeLists.txt (to run them under qemu-system-arm).
# The stack's portable tests (tests/unit/<test>.c), on the host and here;
# each family's own come from its declaration (CO_UNIT_FAMILY_TESTS).
set(CO_STACK_TESTS test_stack test_store test_profile test_hardening test_sdo_edge
  test_store_faults test_node_services test_products_edge test_factory_id test_image)
set(CO_BARE_TESTS ${CO_UNIT_FAMILY_TESTS} ${CO_STACK_TESTS} test_flash_ee test_div test_serial_link)
