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
#include "co_image.h"

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

/** @name Program download (co_progdl.h)
 * Only an image that links the service needs them: the loader side
 * (co_progdl_service: the bootloaders, the Linux program) all but
 * co_port_prog_handover, the application side (a product image run by a
 * bootloader) co_port_prog_handover alone. The program area holds the
 * image (co_image.h) as downloaded, header included, at offsets from 0;
 * where it lies in flash, and what "installed" means there, is the
 * board's. None of these is called while an SDO answer waits, unless
 * said; none is called from an interrupt. @{
 */
/** The loader's state, which the board owns and set up with
 * co_progdl_init(): the same pointer at every call, never NULL. Called at
 * every access to 1F50h-1F57h and every poll of the service. */
struct co_progdl *co_port_progdl(void *port);
/** Whether the image header h (complete, its format checked) is for this
 * board and product and fits its area: CO_PROGDL_OK; CO_PROGDL_FORMAT
 * (another board or product ID); CO_PROGDL_ADDRESS (h->length more than
 * the area, or a load address this board does not run from). The stack
 * checks 1000h and 1018h:1-2 itself. Reads h only, never blocks. */
uint8_t co_port_prog_check(void *port, const co_image_hdr_t *h);
/** Clear (1F51h:1 = 3): make the installed program invalid, for the
 * bootloader and for a power cut alike, before its answer: at most one
 * page erased (the answer is due within 100 ms). False: the flash failed
 * (06060000h, status 5). */
bool co_port_prog_clear(void *port);
/** Write len bytes of the image, buf, at offset at of the area, durable
 * when it returns true. The first write is the header, CO_IMAGE_HDR_SIZE
 * bytes at 0, once checked; then the rest in order, each where the last
 * ended, at most CO_SDO_BUF bytes each and, but for the last, a multiple
 * of 4 bytes long (so each starts at a multiple of 4). The first write into a page
 * erases it (one erase at most: pages are larger than CO_SDO_BUF), inside
 * the SDO answer. at + len never exceeds the length the board accepted
 * (co_port_prog_check). False: the flash failed (06060000h, status 5). */
bool co_port_prog_write(void *port, uint32_t at, const void *buf, uint32_t len);
/** Read len (1 .. CO_PROGDL_VERIFY_STEP) bytes of the area from at into
 * buf, for the check after the download (1F57h busy). False: the flash
 * failed (status 5). */
bool co_port_prog_read(void *port, uint32_t at, void *buf, uint32_t len);
/** The image h describes is in the area whole, its CRC checked as read
 * back: make it the installed program, the one the next start boots
 * (a board that boots whatever checks needs nothing here). Called from a
 * poll, no answer waiting. False: the flash failed (status 5, no
 * program). */
bool co_port_prog_commit(void *port, const co_image_hdr_t *h);
/** Start (1F51h:1 = 1), after its answer went out: boot the installed
 * program (a bootloader resets into it; the Linux program runs it and
 * boots up as it). Need not return. */
void co_port_prog_start(void *port);
/** Stop (1F51h:1 = 0) while started, after its answer went out: the
 * running program stops, and the node stays, 1F51h:1 reading 0 (the Linux
 * program stops its product's work). Need not return (a reset into the
 * bootloader). */
void co_port_prog_stop(void *port);
/** The application side's stop (1F51h:1 = 0), called while its answer is
 * being made: the board sets the flag its bootloader reads and resets
 * once the answer has left (the board's main loop, after
 * co_node_receive() returned). Must return. */
void co_port_prog_handover(void *port);
/** @} */

#endif /* CO_PORT_H */
