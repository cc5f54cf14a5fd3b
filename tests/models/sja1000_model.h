/*
 * sja1000_model.h - a register-level model of the SJA1000 stand-alone CAN
 * controller and the CAN bus around it, written from the NXP (Philips)
 * SJA1000 data sheet (product specification of 2000 Jan 04, section 6.4
 * "PeliCAN mode") for the host unit test of boards/common/sja1000.c
 * (tests/unit/test_sja1000.c). It knows nothing of the driver: its
 * register numbers and bits are its own, from the data sheet's tables.
 *
 * What is modelled, as the data sheet describes it:
 * - Hardware reset: BasicCAN mode (CDR.7 = 0) in reset mode; in BasicCAN
 *   mode only the control register's reset request (address 0, bit 0) and
 *   the clock divider (31) are modelled, a write to any other address is a
 *   violation (there it would hit a BasicCAN register). CDR.7 (PeliCAN),
 *   CDR.6, CDR.5 and CDR.3 are written only in reset mode.
 * - MOD: RM (reset mode), LOM, STM, AFM written only in reset mode; on
 *   entering reset mode a transmission is aborted (TBS 1, TCS kept), the
 *   RX FIFO emptied (RMC 0, RBS 0, DOS 0, RBSA kept) and IR cleared.
 * - Registers written only in reset mode: BTR0, BTR1, OCR, EWLR, RXERR,
 *   TXERR, RBSA, ACR0..3 and AMR0..3 (addresses 16..23 in reset mode); a
 *   write in operating mode is a violation and changes nothing.
 * - Operating mode, addresses 16..28: a write goes to the transmit buffer
 *   (a violation while it is locked, TBS 0: the byte is lost, as the data
 *   sheet says), a read shows the RX FIFO's current message from RBSA on
 *   (wrapping round the 64 bytes; a read with RBS 0 is a violation).
 * - CMR (write only, reads 0xFF): TR, AT, RRB, CDO; TR + AT is a single
 *   shot. TR while a transmission is pending, TR in reset mode and RRB
 *   with an empty FIFO are violations.
 * - SR: RBS, DOS, TBS, TCS, RS, TS (both 1 in reset mode and bus-off), ES,
 *   BS. IR: each bit only when enabled in IER; reading IR clears it, but
 *   RI stays while the FIFO holds a message. TI on TBS 0 -> 1, EI on a
 *   change of ES or BS, EPI on entering or leaving error passive (an error
 *   counter above 127), DOI on DOS 0 -> 1.
 * - RX FIFO of 64 bytes: a message takes its frame information, 2 (SFF) or
 *   4 (EFF) identifier bytes and its data bytes (none for a remote frame,
 *   at most 8); one that does not fit is lost and sets DOS. RMC counts the
 *   messages, RRB releases the current one.
 * - The acceptance filter (6.4.15): single (AFM 1) and dual (AFM 0), for
 *   standard and extended frames, data bytes compared only when the
 *   message has them; AMR bit 1 = don't care.
 * - Error counters as ISO 11898-1 counts a lone transmitter without ACK
 *   (TXERR + 8 an attempt, never above 128 from ACK errors once error
 *   passive) and successes (TXERR - 1 after a frame sent, RXERR - 1 after
 *   one received); ES against EWLR (96 after hardware reset); bus-off when
 *   TXERR would exceed 255: BS 1, RM set by the controller, TXERR 127,
 *   RXERR 0, EI. After the CPU clears RM, 128 occurrences of 11 recessive
 *   bits (sja_model_idle) count TXERR down; then BS 0, ES 0, counters 0,
 *   EI. A CPU write of 0..254 to TXERR during bus-off clears BS at once,
 *   as the data sheet allows, but skips the 128 x 11 bits ISO 11898-1
 *   requires: a violation.
 *
 * Time is the test's: a pending transmission goes out when the test says
 * the bus had room (sja_model_bus), bus-free time passes when it says so
 * (sja_model_idle). Not modelled: sleep mode and wake-up, listen-only and
 * self-test behaviour beyond their MOD bits, self reception, ALC and ECC
 * (read as 0), the test register, BasicCAN operation.
 */
#ifndef SJA1000_MODEL_H
#define SJA1000_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "sja1000.h"

#define SJA_MODEL_SENT_MAX 512u

/* One frame the controller put on the bus. */
typedef struct sja_model_sent {
    uint32_t id; /* 11 or 29 bits */
    bool ext;    /* FI.FF */
    bool rtr;    /* FI.RTR */
    uint8_t dlc; /* FI's DLC field as written (0..15) */
    uint8_t data[8];
} sja_model_sent_t;

typedef struct sja_model {
    /* What the test sets. */
    bool absent;          /* nothing at the address: reads 0xFF, writes lost */
    bool stuck_reset;     /* MOD.RM cannot be cleared */
    bool stuck_operating; /* MOD.RM cannot be set by the CPU */
    bool basic_only;      /* CDR.7 stays 0 (a BasicCAN-only part, PCA82C200) */
    bool no_ack;          /* nobody acknowledges: a transmission stays pending */
    bool acr_broken;      /* not an SJA1000: ACR0 reads back with bit 0 flipped */
    bool basic_echo;      /* with basic_only: address 16 reads back what was
                           * last written to it (a BasicCAN buffer byte) */
    uint8_t basic16;
    unsigned mode_lag; /* a slow part: writes of MOD asking for another mode
                        * (RM set or cleared) it ignores before it takes one */
    /* QEMU's model (hw/net/can/can_sja1000.c, PeliCAN mode) where it departs
     * from the data sheet in what a driver can see: a remote frame goes into
     * the FIFO with as many data bytes as its DLC says (what the sender's
     * frame held there), but CMR.RRB frees only its frame information and
     * identifier, so the next message is read from inside those bytes and
     * they stay counted as used; RMC and RBSA read 0xFF; reset mode leaves
     * the FIFO as it is (QEMU tests the MOD value it has just stored). */
    bool qemu;

    /* Registers (PeliCAN). */
    uint8_t mod, ier, btr0, btr1, ocr, ewlr, rxerr, txerr, cdr, rbsa;
    uint8_t cr_bits; /* BasicCAN control register bits 1..4 */
    uint8_t ir;      /* latched interrupt bits (RI is computed) */
    bool dos, tcs, es, bs, passive;
    uint8_t acr[4], amr[4];
    uint8_t txb[13];
    uint8_t fifo[64];
    uint8_t rx_bytes; /* bytes of the FIFO in use, from rbsa on */
    uint8_t rmc;
    bool tx_pending, single_shot;
    unsigned idle_seen; /* bus-free occurrences since the bus-off recovery began */

    /* What the model records. */
    sja_model_sent_t sent[SJA_MODEL_SENT_MAX];
    unsigned nsent;
    unsigned taken;         /* sent[] entries the test has looked at (sja_model_next) */
    unsigned reset_entries; /* reset mode entered by a CPU write of MOD */
    unsigned aborts;        /* transmissions aborted (CMR.AT) */
    unsigned lost;          /* messages that did not fit into the FIFO */
    unsigned reads, writes;
    unsigned violations;
    char last_violation[160];
} sja_model_t;

/* The accessor for sja1000_init (ctx: the sja_model_t). */
extern const sja1000_io_t sja_model_io;
uint8_t sja_model_read(void *ctx, uint8_t reg);
void sja_model_write(void *ctx, uint8_t reg, uint8_t value);

/* A new chip after a hardware reset (everything recorded cleared). */
void sja_model_new(sja_model_t *m);

/* Whether the acceptance filter as programmed lets this message through. */
bool sja_model_accepts(const sja_model_t *m, uint32_t id, bool ext, bool rtr, uint8_t dlc,
                       const uint8_t *data);

/* A message on the bus from another node: stored into the RX FIFO when the
 * controller is on the bus (operating mode, not bus-off), the filter
 * accepts it and it fits (else DOS). True when stored. */
bool sja_model_rx(sja_model_t *m, uint32_t id, bool ext, bool rtr, uint8_t dlc,
                  const uint8_t *data);

/* The bus had room for one frame: a pending transmission goes out (false:
 * none pending, off the bus, or no ACK: then the error counter grows). */
bool sja_model_bus(sja_model_t *m);

/* The next frame sent that the test has not looked at, or NULL. */
const sja_model_sent_t *sja_model_next(sja_model_t *m);

/* The bus's errors brought the counters to rx and tx (tx > 255: bus-off). */
void sja_model_errors(sja_model_t *m, unsigned rx, unsigned tx);

/* n occurrences of 11 recessive bits (bus-free) passed. */
void sja_model_idle(sja_model_t *m, unsigned n);

/* Violations since the last call (each was printed when it happened). */
unsigned sja_model_take_violations(sja_model_t *m);

#endif /* SJA1000_MODEL_H */
