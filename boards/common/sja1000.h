/*
 * sja1000.h - a driver for the SJA1000 stand-alone CAN controller in its
 * PeliCAN mode (NXP SJA1000 data sheet, "PeliCAN mode"), for any board
 * that has one: a PCI card's I/O port, a memory-mapped core, or an MCU
 * peripheral of the same family (the TWAI of the ESP32 parts keeps the
 * PeliCAN register map). The board gives two functions that read and write
 * one controller register by its PeliCAN address (0..31); everything else
 * is here, with no global state: the driver's state is sja1000_t.
 *
 * What it does:
 *  - init: reset mode, PeliCAN mode (clock divider CDR.7), the receive,
 *    transmit, error warning, data overrun and error passive interrupts
 *    enabled (not wake-up, bus error, arbitration lost), output control normal,
 *    acceptance filter open, bit timing, then operating mode;
 *  - bit timing (BTR0/BTR1) for every CiA 301 bit rate from the controller's
 *    clock, by the data sheet's formula (sja1000_timing);
 *  - the acceptance filter from the node's receive list (co_node_rx_ids):
 *    the two filters of dual-filter mode, chosen to let through as few
 *    other CAN-IDs as they can, and an exact software check behind them,
 *    since two code/mask pairs cannot express every list;
 *  - receive from the RX FIFO; transmit through the transmit buffer with a
 *    software queue behind it, in order; a frame the queue cannot take is
 *    refused (sja1000_send returns false: the stack counts it as dropped),
 *    never lost silently;
 *  - data overruns counted; the error state from the status register and
 *    the error counters, mapped to co_can_state_t; after bus-off the
 *    controller is restarted at once (the SJA1000 then waits 128 x 11
 *    recessive bits before it takes part in the bus again), and the queue
 *    goes on where it stopped.
 *
 * Call order: sja1000_init, then sja1000_service from the main loop
 * (after each interrupt, or at least every SJA1000_SERVICE_BOUND_US: see
 * there) with sja1000_receive, sja1000_send and sja1000_state as needed.
 * None of these blocks; interrupt handlers need not call any of them (the
 * SJA1000 keeps its interrupt line asserted until its interrupt register
 * is read, which wakes a sleeping core).
 */
#ifndef SJA1000_H
#define SJA1000_H

#include "co_common.h"
#include "co_node.h"

/* PeliCAN register addresses (data sheet, PeliCAN address allocation). */
enum {
    SJA_MOD = 0,   /* mode */
    SJA_CMR = 1,   /* command (write only) */
    SJA_SR = 2,    /* status */
    SJA_IR = 3,    /* interrupt (reading clears it) */
    SJA_IER = 4,   /* interrupt enable */
    SJA_BTR0 = 6,  /* bus timing 0: SJW, BRP (reset mode) */
    SJA_BTR1 = 7,  /* bus timing 1: SAM, TSEG2, TSEG1 (reset mode) */
    SJA_OCR = 8,   /* output control (reset mode) */
    SJA_EWLR = 13, /* error warning limit */
    SJA_RXERR = 14,
    SJA_TXERR = 15,
    SJA_FRAME = 16, /* operating mode: TX/RX frame information, then ID and data;
                     * reset mode: ACR0..3 at 16..19, AMR0..3 at 20..23 */
    SJA_ACR0 = 16,
    SJA_AMR0 = 20,
    SJA_RMC = 29, /* RX message counter */
    SJA_CDR = 31, /* clock divider */
};

/* Register bits used here. */
#define SJA_MOD_RM 0x01u  /* reset mode */
#define SJA_MOD_AFM 0x08u /* single acceptance filter (clear: dual) */
#define SJA_CMR_TR 0x01u  /* transmission request */
#define SJA_CMR_AT 0x02u  /* abort transmission */
#define SJA_CMR_RRB 0x04u /* release receive buffer */
#define SJA_CMR_CDO 0x08u /* clear data overrun */
#define SJA_SR_RBS 0x01u  /* receive buffer status: a frame is in the FIFO */
#define SJA_SR_DOS 0x02u  /* data overrun */
#define SJA_SR_TBS 0x04u  /* transmit buffer released */
#define SJA_SR_ES 0x40u   /* an error counter reached the warning limit */
#define SJA_SR_BS 0x80u   /* bus-off */
#define SJA_IR_RI 0x01u
#define SJA_IR_TI 0x02u
#define SJA_IR_EI 0x04u /* error warning: ES or BS changed */
#define SJA_IR_DOI 0x08u
#define SJA_IR_EPI 0x20u /* error passive entered or left */
#define SJA_CDR_PELICAN 0x80u
#define SJA_CDR_CLKOFF 0x08u /* CLKOUT pin off */
#define SJA_OCR_NORMAL 0x1Au /* normal output mode, TX0 push-pull */
#define SJA_FI_FF 0x80u      /* frame information: extended frame */
#define SJA_FI_RTR 0x40u

/* Frames the software transmit queue holds behind the transmit buffer. */
#ifndef SJA1000_TXQ_LEN
#define SJA1000_TXQ_LEN 16u
#endif
/* CAN-IDs the acceptance filter is computed for (the nodes' lists
 * together, without duplicates); a longer list opens the hardware filter
 * and leaves it to the software check. */
#define SJA1000_IDS_MAX (2u * CO_NODE_RX_IDS_MAX)
_Static_assert(SJA1000_IDS_MAX <= 255u && SJA1000_TXQ_LEN <= 255u,
               "nids, tx_head and tx_len are bytes");
/* At most this many IDs get the exact two-filter choice (2^(n-1)
 * partitions are tried); more get a greedy one. */
#define SJA1000_EXACT_IDS 12u
/*
 * The longest a board may leave between two sja1000_service calls without
 * an interrupt: the RX FIFO (64 bytes) holds 5 frames of 8 data bytes at
 * the least, which take 5 x 111 bit times = 555 us at 1 Mbit/s.
 */
#define SJA1000_SERVICE_BOUND_US 500u

/* The board's access to one register (PeliCAN address 0..31). */
typedef struct sja1000_io {
    uint8_t (*read)(void *ctx, uint8_t reg);
    void (*write)(void *ctx, uint8_t reg, uint8_t value);
} sja1000_io_t;

typedef struct sja1000 {
    const sja1000_io_t *io;
    void *ctx;
    uint32_t clock_hz; /* the controller's oscillator (fosc, XTAL1) */
    uint16_t kbps;     /* the bit rate programmed */
    /* The receive list the filter was computed for (exact match behind the
     * hardware filter), and whether there is one at all (before the first
     * sja1000_set_filter every frame passes). */
    co_rx_id_t ids[SJA1000_IDS_MAX];
    uint8_t nids;
    bool filtered;
    bool filter_pending; /* acr/amr not yet in the controller */
    uint8_t acr[4];      /* the acceptance code and mask as programmed */
    uint8_t amr[4];
    /* Transmit queue: frames waiting for the transmit buffer, oldest at head. */
    co_frame_t txq[SJA1000_TXQ_LEN];
    uint8_t tx_head;
    uint8_t tx_len;
    bool tx_busy;          /* the head is in the transmit buffer */
    uint8_t state;         /* co_can_state_t, as of the last sja1000_service */
    uint32_t overruns;     /* data overruns (frames lost in the controller) */
    uint32_t filtered_out; /* frames the software check dropped */
    uint32_t restarts;     /* bus-off recoveries started */
    /* A controller that keeps a remote frame's data bytes in its RX FIFO
     * but frees only its header (QEMU's model: known by its RMC, see
     * sja1000_init); once such a frame was released the FIFO is out of
     * step for good, and the frames after it are released unread. */
    bool rtr_skews;
    bool out_of_step;
    uint32_t unread; /* frames released unread since */
} sja1000_t;

/*
 * BTR0 and BTR1 for kbps at oscillator clock_hz (data sheet, bus timing
 * registers: tscl = 2 x tCLK x (BRP + 1); a bit is 1 + (TSEG1 + 1) +
 * (TSEG2 + 1) time quanta). Of the settings with 8..25 quanta per bit that
 * give kbps exactly, the one whose sample point is nearest 87.5 % (CiA
 * 301's recommendation), on a tie the one with more quanta; SJW =
 * min(TSEG2 quanta, 4). False (nothing written) when none gives kbps.
 */
bool sja1000_timing(uint32_t clock_hz, uint16_t kbps, uint8_t *btr0, uint8_t *btr1);

/*
 * Brings the controller up at kbps, filter open, transmit queue empty.
 * False when the controller does not answer as an SJA1000 (reset mode or
 * PeliCAN mode not entered) or kbps cannot be timed; it is then left in
 * reset mode (off the bus).
 */
bool sja1000_init(sja1000_t *c, const sja1000_io_t *io, void *ctx, uint32_t clock_hz,
                  uint16_t kbps);

/* Reprograms the bit timing (reset mode and back; the filter and the
 * transmit queue are kept, a frame in the transmit buffer is sent again).
 * False, nothing changed, when kbps cannot be timed. */
bool sja1000_set_bitrate(sja1000_t *c, uint16_t kbps);

/*
 * The receive list: the nodes' co_node_rx_ids() together (n entries;
 * duplicates allowed). Reprograms the acceptance filter only when the
 * list differs from the last one. A change goes through reset mode, which
 * empties the RX FIFO: it waits until the FIFO is empty (this call or a
 * later sja1000_service), and only a frame arriving during the change
 * itself is lost; the software check takes the new list at once. More
 * than SJA1000_IDS_MAX distinct IDs: the hardware filter is opened and
 * nothing is dropped. Then moves the next queued frame into a free
 * transmit buffer, as sja1000_service does.
 */
void sja1000_set_filter(sja1000_t *c, const co_rx_id_t *ids, unsigned n);

/* Queues f for sending (in order behind the frames queued before); it goes
 * into the transmit buffer at the next sja1000_service or
 * sja1000_set_filter, not here: a board that filters changes its filter
 * before what the same main-loop pass produced leaves (a node's boot-up
 * under a new node-ID goes out with the filter already passing the new
 * SDO request, which a master sends at once). False when the queue is
 * full or the controller is bus-off: f is not sent. */
bool sja1000_send(sja1000_t *c, const co_frame_t *f);

/*
 * The next received frame that passes the receive list, in *f; false when
 * the FIFO holds none. Extended frames (CANopen here uses 11-bit IDs) and
 * frames not on the list are released and skipped; at most the FIFO's
 * content is read in one call. On a controller with rtr_skews, a remote
 * frame with a DLC above 0 is the last frame read: it is returned, and
 * from then on every frame is released unread (out_of_step, unread), since
 * its bytes would be read from the wrong place; only a new sja1000_init
 * of a controller that starts afresh ends that (QEMU's: a new QEMU).
 */
bool sja1000_receive(sja1000_t *c, co_frame_t *f);

/*
 * The interrupt's work, from the main loop: reads the interrupt register
 * (which releases the interrupt line), counts and clears a data overrun,
 * moves the next queued frame into a free transmit buffer, puts a waiting
 * filter change into the controller (sja1000_set_filter), updates the
 * error state, and restarts the controller after bus-off (the queue is
 * kept). Returns the state.
 */
co_can_state_t sja1000_service(sja1000_t *c);

/* The error state as of the last sja1000_service. */
static inline co_can_state_t sja1000_state(const sja1000_t *c)
{
    return (co_can_state_t)c->state;
}

#endif /* SJA1000_H */
