/*
 * mcu_main_fixed.c - boards/common/mcu_main.c built for the host tests
 * (test_board_common.c) as an image whose fixed node config (CO_FIXED_CFG)
 * is not its product's: the DST X730 with the X710's config. The main loop
 * must refuse to run it (red LED) rather than run the wrong config.
 */
#define main mcu_main_fixed
#define PRODUCT_SYM dst_x730_xy30
#define PRODUCT_HEADER "dst.h"
#define PRODUCT_INST_SIZE sizeof(dst_dev_t)
#define CO_FIXED_CFG dst_x710_cfg
/* The port function is test_board_common.c's copy of mcu_main.c's (this
 * image never starts a node): renamed here, so that it is defined once. */
#define co_port_can_bitrate mcu_main_fixed_can_bitrate
#include "co_common.h"
bool co_port_can_bitrate(void *port, uint16_t kbps);
int main(void); /* mcu_main_fixed: declared, for -Wmissing-prototypes */
#include "mcu_main.c"
