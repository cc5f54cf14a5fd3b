/** @file
 * co_port.h - what a board must provide to the stack.
 *
 * Every function takes the board context the node was created with
 * (co_node_t.port); the stack never interprets it. There are no weak
 * defaults: a board that misses one of these fails to link.
 * None of these is called from interrupt context by the stack; the stack
 * itself runs in the board's main loop.
 */
#ifndef CO_PORT_H
#define CO_PORT_H

#include "co_common.h"

/**
 * Queue one frame for transmission. Must not block.
 * Returns true when the frame was queued, false when the transmit queue is
 * full (the frame is lost; the stack counts it and goes on).
 */
bool co_port_can_send(void *port, const co_frame_t *frame);

/**
 * Bring the CAN controller to kbps kbit/s. Called at start and whenever
 * the node's active bit rate changes: a reset that activates another
 * bit-rate code, and LSS "activate bit timing" (CiA 305) after its switch
 * delay. kbps 0: the active code names no bit rate (an unusable stored
 * code; the board picks its default). Returns false when the board cannot
 * run at that rate (it keeps the one it has; the stack goes on).
 */
bool co_port_can_bitrate(void *port, uint16_t kbps);

/** @name EEPROM emulation
 * EEPROM emulation: byte-addressed non-volatile memory; a node's records
 * take CO_STORE_NVM_SIZE bytes from its nvm_base (co_node_init, co_store.h).
 * A read of never-written memory returns 0xFF. Reads and writes are
 * synchronous; a write returns only when the bytes are durable. Both
 * return false on a hardware failure (nothing is retried), and for any
 * byte beyond the board's EEPROM (nothing is read or written then).
 *
 * Decision: the port has no size query. A check of it at start would
 * only say earlier what the range rule above already makes loud: a board
 * whose EEPROM is too small for a node's slots fails those reads, so the
 * store reports the class as CO_STORE_HW (co_store.h), the product shows
 * its data-set error (DST 0x4001 bit 6 and EMCY 1000h; P+F and JD EMCY
 * 6300h; the GSH-A has none), the Linux program logs the set it could not
 * read, and every save is refused with 0x06060000. The check would cost
 * the DST X730 image flash it does not have to spare. @{
 */
/** Copy len bytes of the EEPROM from addr into buf (the caller's, len
 * bytes). False: a hardware failure or a byte beyond the EEPROM; buf's
 * contents are then undefined. */
bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len);
/** Write len bytes of buf (read only during the call) to the EEPROM at
 * addr; durable when it returns true. False: a hardware failure or a byte
 * beyond the EEPROM (what the bytes hold then is undefined: the store's
 * records survive it, co_store.h). */
bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len);
/** The len bytes from addr hold nothing the stack will read again before
 * it writes them, and its next write there starts a record at addr: a
 * board whose memory must be erased before it is written (flash) may
 * erase them now, so that the write that follows needs no erase. The stack
 * calls it only while no SDO answer is due (at start before the boot-up,
 * and after CO_STORE_QUIET_US without a request: co_store.h), so that an
 * erase of tens of milliseconds never delays an answer. Nothing to do for
 * memory written in place (a file, a real EEPROM). A failure is not
 * reported: the write that follows erases then, or fails itself. */
void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len);
/** @} */

#endif /* CO_PORT_H */
