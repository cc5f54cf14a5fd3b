# The unit tests that also run on the emulated Cortex-M0 (all but the Linux
# board's): read by tests/qemu/CMakeLists.txt (to build them) and by
# tests/CMakeLists.txt (to run them under qemu-system-arm).
set(CO_BARE_TESTS test_dst_manual test_pf_manual test_gsh_manual test_jd_manual
  test_stack test_store test_profile test_hardening test_flash_ee test_div)
