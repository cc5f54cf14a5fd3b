/*
 * board.h - what a bare-metal board provides to the MCU main loop
 * (mcu_main.c), besides the stack's own co_port.h. One line per function.
 * Interrupt handlers only queue; everything else runs in the main loop.
 */
#ifndef BOARD_H
#define BOARD_H

#include "co_common.h"
#include "co_node.h"
#include "product.h"

/* Clocks, pins, timer, the CAN controller's clock and receive interrupt;
 * returns false on a fault. The bit rate comes later: the node's start
 * asks for it (co_port_can_bitrate -> board_can_bitrate). */
bool board_init(void);
/* Bring the CAN controller to a bit rate (kbit/s); false if it cannot. */
bool board_can_bitrate(uint16_t kbps);
/* Free-running microseconds (wraps every 71 minutes). */
uint32_t board_now_us(void);
/* Take one received frame from the interrupt's queue; false when empty. */
bool board_can_receive(co_frame_t *f);
/* The CAN controller's error state (co_can_state_t). */
uint8_t board_can_state(void);
/* Drive the two status LEDs. */
void board_leds(bool green, bool red);
/* One sensor sample of product p's inputs, in thousandths of their unit. */
void board_sensor(const product_t *p, int32_t values[], uint32_t *faults);
/* The serial number (0x1018 sub 4) of node i (0 or 1): from the chip's
 * unique ID where it has one (uid_serial.h), never 0, the nodes differ. */
uint32_t board_serial(unsigned node);
/* Sleep until an interrupt or about us microseconds have passed. */
void board_sleep(uint32_t us);
/* Boards built with BOARD_RX_FILTER (a controller with acceptance
 * filters): the nodes' receive lists together (co_node_rx_ids), after every
 * main-loop pass; the board reprograms its filter when they changed. */
void board_can_filter(const co_rx_id_t *ids, unsigned n);

#endif /* BOARD_H */
