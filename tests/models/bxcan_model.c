/*
 * bxcan_model.c - the bxCAN controller of the STM32F042 (RM0091 section
 * "Controller area network (bxCAN)") and the CAN bus around it, at
 * register level, for the host tests (see stm32f042_model.h).
 *
 * What is modelled, as the manual describes it:
 * - Operating modes: sleep after reset (SLAK), initialization (INRQ ->
 *   INAK), normal; a request completes only after the code has read
 *   CAN_MSR twice (the acknowledge takes time), and the move to normal mode
 *   needs 11 recessive bits on the bus (never while it is held dominant).
 *   INRQ and SLEEP both set request nothing (the state diagram leaves on
 *   one of them alone).
 * - CAN_BTR: written or read only in initialization mode; reserved bits
 *   kept at their reset value.
 * - Three transmit mailboxes: TIxR, TDTxR, TDLxR, TDHxR written only while
 *   the mailbox is empty (TME); TXRQ makes it pending; the bus takes them
 *   in request order (TXFP set) or by identifier, lower mailbox first on a
 *   tie (TXFP clear); completion sets RQCP and TXOK, and TME again; ABRQ
 *   aborts a pending request.
 * - Receive FIFOs of three messages: FMP count, FULL, FOVR with the
 *   overrun rule of RFLM (the newest message lost when locked, else the
 *   last stored one overwritten), RFOM releasing the output mailbox;
 *   reading an empty FIFO's output mailbox is undefined (a violation); all
 *   receive registers are read-only.
 * - Filters: 14 banks, scale (FS1R), mode (FM1R), FIFO (FFA1R), activation
 *   (FA1R). FM1R, FS1R and FFA1R are written only with FINIT set (filter
 *   initialization, during which nothing is received); a bank is
 *   reconfigured only while deactivated; CAN_FiRx is written only while
 *   its bank is deactivated or FINIT is set; reserved bits (FMR's
 *   included) keep their reset value. A frame goes to the FIFO of the
 *   matching filter of highest priority (32-bit before 16-bit, list
 *   before mask, lower number first); the filter match index is numbered
 *   per FIFO.
 * - Error management: TEC and REC as ISO 11898-1 counts them, EWGF at 96,
 *   EPVF above 127, bus-off when TEC exceeds 255: no traffic; recovery
 *   after 128 periods of 11 recessive bits in normal mode, started
 *   automatically with ABOM, else by entering and leaving initialization
 *   mode; counters 0 after it.
 * - The interrupt request of the F0's single CAN vector: TMEIE (RQCPx),
 *   FMPIE0/1, FFIE0/1, FOVIE0/1, ERRIE with EWGIE/EPVIE/BOFIE (ERRI).
 */
#include <string.h>

#include "stm32f042_parts.h"

#define MCR_INRQ (1u << 0)
#define MCR_SLEEP (1u << 1)
#define MCR_TXFP (1u << 2)
#define MCR_RFLM (1u << 3)
#define MCR_NART (1u << 4)
#define MCR_ABOM (1u << 6)
#define MCR_RESET (1u << 15)
#define MCR_WRITABLE 0x000180FFu /* DBF, RESET, TTCM..INRQ */

#define MSR_INAK (1u << 0)
#define MSR_SLAK (1u << 1)
#define MSR_ERRI (1u << 2)

#define IER_TMEIE (1u << 0)
#define IER_FMPIE0 (1u << 1)
#define IER_FFIE0 (1u << 2)
#define IER_FOVIE0 (1u << 3)
#define IER_EWGIE (1u << 8)
#define IER_EPVIE (1u << 9)
#define IER_BOFIE (1u << 10)
#define IER_ERRIE (1u << 15)

#define BTR_WRITABLE 0xC37F03FFu /* SILM, LBKM, SJW, TS2, TS1, BRP */
#define BANKS 14u
#define BANK_MASK ((1u << BANKS) - 1u)
#define FMR_RESET 0x2A1C0E01u

typedef struct mailbox {
    uint32_t tir, tdtr, tdlr, tdhr;
    bool pending;
    unsigned order; /* request order (TXFP) */
} mailbox_t;

typedef struct rx_msg {
    uint32_t rir, rdtr, rdlr, rdhr;
} rx_msg_t;

typedef struct fifo {
    rx_msg_t msg[3];
    unsigned count;
    bool full, ovr;
} fifo_t;

static struct {
    uint32_t mcr;
    stm_can_mode_t mode;
    stm_can_mode_t target; /* requested mode */
    unsigned ack_wait;     /* MSR reads until the request completes */
    uint32_t msr_flags;    /* ERRI, WKUI, SLAKI */
    uint32_t ier;
    uint32_t lec;
    uint32_t btr;
    mailbox_t tx[3];
    uint32_t tsr_flags; /* RQCP, TXOK, ALST, TERR of each mailbox */
    unsigned next_order;
    fifo_t fifo[2];
    uint32_t fmr, fm1r, fs1r, ffa1r, fa1r;
    uint32_t fr[BANKS][2];
    unsigned tec; /* 9 bits and more: bus-off above 255 */
    unsigned rec;
    bool bus_off;
    bool recovery_armed;    /* ABOM clear: init entered and left since bus-off */
    unsigned recovery_seen; /* periods of 11 recessive bits in bus-off */
    bool stuck;             /* the bus held dominant */
    uint32_t esr_seen;      /* error flags at the last ERRI evaluation */
} can;

void bxcan_reset(void)
{
    uint32_t fr[BANKS][2];
    memcpy(fr, can.fr, sizeof(fr));
    bool stuck = can.stuck;
    memset(&can, 0, sizeof(can));
    can.stuck = stuck;     /* the bus is not part of the chip */
    can.mcr = 0x00010002u; /* DBF, SLEEP */
    can.mode = STM_CAN_SLEEP;
    can.target = STM_CAN_SLEEP;
    can.btr = 0x01230000u;
    can.fmr = FMR_RESET;
    for (unsigned i = 0; i < 3u; i++) {
        /* Undefined after reset but for TXRQ: a pattern a driver must not rely on. */
        can.tx[i].tir = 0xA5A5A5A4u;
        can.tx[i].tdtr = 0x5A5A5A5Au;
    }
    for (unsigned i = 0; i < BANKS; i++) {
        can.fr[i][0] = 0xC3C3C3C3u ^ i; /* undefined after reset */
        can.fr[i][1] = 0x3C3C3C3Cu ^ i;
    }
}

/* ---- status ------------------------------------------------------------- */

static uint32_t esr_flags(void)
{
    uint32_t f = 0;
    if (can.tec >= 96u || can.rec >= 96u) {
        f |= 1u; /* EWGF */
    }
    if (can.tec > 127u || can.rec > 127u) {
        f |= 2u; /* EPVF */
    }
    if (can.bus_off) {
        f |= 4u; /* BOFF */
    }
    return f;
}

/* ERRI: set when an error flag enabled in IER newly sets (ERRIE gates the request). */
static void errors_changed(void)
{
    uint32_t now = esr_flags();
    uint32_t rising = now & ~can.esr_seen;
    uint32_t enabled = ((can.ier & IER_EWGIE) != 0u ? 1u : 0u) |
                       ((can.ier & IER_EPVIE) != 0u ? 2u : 0u) |
                       ((can.ier & IER_BOFIE) != 0u ? 4u : 0u);
    if ((rising & enabled) != 0u) {
        can.msr_flags |= MSR_ERRI;
    }
    can.esr_seen = now;
}

static bool on_bus(void)
{
    return can.mode == STM_CAN_NORMAL && !can.bus_off;
}

stm_can_mode_t stm_can_mode(void)
{
    return can.mode;
}

unsigned stm_can_tec(void)
{
    return can.tec;
}

unsigned stm_can_rec(void)
{
    return can.rec;
}

unsigned stm_can_fmp0(void)
{
    return can.fifo[0].count;
}

unsigned stm_can_tx_pending(void)
{
    return (unsigned)can.tx[0].pending + can.tx[1].pending + can.tx[2].pending;
}

bool bxcan_irq_line(void)
{
    uint32_t ier = can.ier;
    bool rq = (ier & IER_TMEIE) != 0u && (can.tsr_flags & 0x00010101u) != 0u;
    for (unsigned f = 0; f < 2u; f++) {
        uint32_t e = ier >> (3u * f);
        rq = rq || ((e & IER_FMPIE0) != 0u && can.fifo[f].count > 0u);
        rq = rq || ((e & IER_FFIE0) != 0u && can.fifo[f].full);
        rq = rq || ((e & IER_FOVIE0) != 0u && can.fifo[f].ovr);
    }
    return rq || ((ier & IER_ERRIE) != 0u && (can.msr_flags & MSR_ERRI) != 0u);
}

/* ---- modes ------------------------------------------------------------------ */

static void request_mode(void)
{
    bool inrq = (can.mcr & MCR_INRQ) != 0u;
    bool sleep = (can.mcr & MCR_SLEEP) != 0u;
    stm_can_mode_t want;
    if (inrq && !sleep) {
        want = STM_CAN_INIT;
    } else if (sleep && !inrq) {
        want = STM_CAN_SLEEP;
    } else if (!inrq && !sleep) {
        want = STM_CAN_NORMAL;
    } else {
        can.target = can.mode; /* both: no transition of the state diagram (a pending one is off) */
        can.ack_wait = 0;
        return;
    }
    if (want != can.target || want != can.mode) {
        can.target = want;
        can.ack_wait = 2u;
    }
}

static void mode_reached(stm_can_mode_t m)
{
    stm_can_mode_t from = can.mode;
    can.mode = m;
    if (m == STM_CAN_INIT && can.bus_off && (can.mcr & MCR_ABOM) == 0u) {
        can.recovery_armed = false; /* left below: armed then */
    }
    if (from == STM_CAN_INIT && m == STM_CAN_NORMAL && can.bus_off) {
        can.recovery_armed = true; /* software started the recovery (ABOM clear) */
    }
    if (m == STM_CAN_SLEEP) {
        can.msr_flags |= 1u << 4; /* SLAKI */
    }
    stm_progress();
}

/* One read of CAN_MSR: pending acknowledges advance. */
static void msr_tick(void)
{
    if (can.target == can.mode || can.ack_wait == 0u) {
        return;
    }
    if (--can.ack_wait > 0u) {
        return;
    }
    if (can.target == STM_CAN_NORMAL && can.stuck) {
        can.ack_wait = 1u; /* waits for 11 recessive bits */
        return;
    }
    mode_reached(can.target);
}

/* ---- transmission -------------------------------------------------------- */

/* The CAN arbitration field as one number, lower wins: identifier, then
 * RTR (standard) or SRR and IDE (extended), as the bits go on the bus. */
static uint64_t arbitration(uint32_t tir)
{
    uint64_t stid = tir >> 21;
    bool ide = (tir & 4u) != 0u;
    bool rtr = (tir & 2u) != 0u;
    if (!ide) {
        return (stid << 21) | ((uint64_t)rtr << 20); /* IDE (dominant) at bit 19 */
    }
    uint64_t exid = (tir >> 3) & 0x3FFFFu;
    return (stid << 21) | (1u << 20) | (1u << 19) | (exid << 1) | (uint64_t)rtr;
}

static int next_mailbox(void)
{
    int best = -1;
    for (int i = 0; i < 3; i++) {
        if (!can.tx[i].pending) {
            continue;
        }
        if (best < 0) {
            best = i;
        } else if ((can.mcr & MCR_TXFP) != 0u
                       ? can.tx[i].order < can.tx[best].order
                       : arbitration(can.tx[i].tir) < arbitration(can.tx[best].tir)) {
            best = i;
        }
    }
    return best;
}

static void tx_done(int i, bool ok)
{
    can.tx[i].pending = false;
    uint32_t shift = 8u * (uint32_t)i;
    can.tsr_flags &= ~(0xFFu << shift);
    can.tsr_flags |= (ok ? 3u : 9u) << shift; /* RQCP and TXOK, or RQCP and TERR */
    stm_progress();
}

/* The 11 recessive bits that separate two frames (acknowledge delimiter,
 * end of frame, intermission): they let a controller that left
 * initialization join the bus, and count for a bus-off recovery. */
static void frame_gap(void)
{
    stm_can_bus_idle(1);
}

bool stm_can_bus_take(stm_can_frame_t *f)
{
    int i = next_mailbox();
    if (i < 0 || can.stuck || can.bus_off) {
        return false; /* nothing to send, or the controller may not */
    }
    frame_gap();
    if (!on_bus()) {
        return false;
    }
    const mailbox_t *m = &can.tx[i];
    memset(f, 0, sizeof(*f));
    f->ide = (m->tir & 4u) != 0u;
    f->rtr = (m->tir & 2u) != 0u;
    f->id = f->ide ? m->tir >> 3 : m->tir >> 21;
    f->dlc = (uint8_t)(m->tdtr & 0xFu);
    for (unsigned b = 0; b < 4u; b++) {
        f->data[b] = (uint8_t)(m->tdlr >> (8u * b));
        f->data[4u + b] = (uint8_t)(m->tdhr >> (8u * b));
    }
    if (f->rtr) {
        memset(f->data, 0, sizeof(f->data)); /* a remote frame carries no data */
    }
    tx_done(i, true);
    can.lec = 0;
    if (can.tec > 0u) {
        can.tec--;
    }
    errors_changed();
    return true;
}

void stm_can_bus_tx_error(bool ack_error)
{
    int i = next_mailbox();
    if (i < 0 || !on_bus()) {
        return;
    }
    can.lec = ack_error ? 3u : 4u; /* acknowledgment error, bit recessive error */
    if (!(ack_error && can.tec > 127u && can.tec <= 255u)) {
        can.tec += 8u;
    }
    if (can.tec > 255u) {
        can.bus_off = true;
        can.recovery_seen = 0;
        can.recovery_armed = (can.mcr & MCR_ABOM) != 0u;
    }
    if ((can.mcr & MCR_NART) != 0u) {
        tx_done(i, false); /* one shot: the request completes, failed */
    }
    errors_changed();
    stm_progress();
}

void stm_can_bus_rx_error(unsigned n)
{
    if (!on_bus()) {
        return;
    }
    can.rec = can.rec + n > 255u ? 255u : can.rec + n;
    can.lec = 1u; /* stuff error */
    errors_changed();
    stm_progress();
}

void stm_can_bus_idle(unsigned n)
{
    if (can.stuck) {
        return;
    }
    if (can.bus_off && can.mode == STM_CAN_NORMAL) {
        bool armed = (can.mcr & MCR_ABOM) != 0u || can.recovery_armed;
        if (armed) {
            can.recovery_seen += n;
            if (can.recovery_seen >= 128u) {
                can.bus_off = false;
                can.tec = 0;
                can.rec = 0;
                errors_changed();
            }
        }
    }
    if (can.target == STM_CAN_NORMAL && can.mode != STM_CAN_NORMAL && can.ack_wait > 0u) {
        mode_reached(STM_CAN_NORMAL);
    }
    stm_progress();
}

void stm_can_bus_stuck_dominant(bool on)
{
    can.stuck = on;
    stm_progress();
}

/* ---- reception and filters --------------------------------------------------- */

/* The frame in the 32-bit filter layout (that of CAN_RIxR). */
static uint32_t key32(const stm_can_frame_t *f)
{
    uint32_t k = f->ide ? (f->id & 0x1FFFFFFFu) << 3 : (f->id & 0x7FFu) << 21;
    return k | (f->ide ? 4u : 0u) | (f->rtr ? 2u : 0u);
}

/* The 16-bit layout: STID, RTR, IDE, EXID[17:15]. */
static uint32_t key16(const stm_can_frame_t *f)
{
    uint32_t k32 = key32(f);
    return ((k32 >> 21) << 5) | (f->rtr ? 0x10u : 0u) | (f->ide ? 8u : 0u) | ((k32 >> 18) & 7u);
}

/* Filters of a bank: 1 (32-bit mask), 2 (32-bit list, 16-bit mask), 4 (16-bit list). */
static unsigned bank_filters(unsigned b)
{
    bool wide = (can.fs1r >> b) & 1u;
    bool list = (can.fm1r >> b) & 1u;
    return wide ? (list ? 2u : 1u) : (list ? 4u : 2u);
}

/* Which filter k of bank b (if any) accepts the frame; returns -1 or k. */
static int bank_match(unsigned b, const stm_can_frame_t *f)
{
    bool wide = (can.fs1r >> b) & 1u;
    bool list = (can.fm1r >> b) & 1u;
    uint32_t r1 = can.fr[b][0];
    uint32_t r2 = can.fr[b][1];
    if (wide) {
        uint32_t k = key32(f);
        if (!list) {
            return ((k ^ r1) & r2 & ~1u) == 0u ? 0 : -1;
        }
        return (k & ~1u) == (r1 & ~1u) ? 0 : ((k & ~1u) == (r2 & ~1u) ? 1 : -1);
    }
    uint32_t k = key16(f);
    if (!list) {
        if (((k ^ r1) & (r1 >> 16) & 0xFFFFu) == 0u) {
            return 0;
        }
        return ((k ^ r2) & (r2 >> 16) & 0xFFFFu) == 0u ? 1 : -1;
    }
    uint32_t ids[4] = {r1 & 0xFFFFu, r1 >> 16, r2 & 0xFFFFu, r2 >> 16};
    for (int i = 0; i < 4; i++) {
        if (ids[i] == k) {
            return i;
        }
    }
    return -1;
}

int stm_can_bus_send(const stm_can_frame_t *f)
{
    if (can.stuck) {
        return STM_CAN_OFF_BUS; /* nobody can send */
    }
    frame_gap();
    if (!on_bus() || (can.fmr & 1u) != 0u) {
        /* Off the bus, or filters in initialization (reception deactivated).
         * A node in normal mode still acknowledges: not modelled apart. */
        return STM_CAN_OFF_BUS;
    }
    /* A correct reception counts, whether a filter takes the frame or not. */
    can.rec = can.rec > 128u ? 120u : (can.rec > 0u ? can.rec - 1u : 0u);
    can.lec = 0;
    errors_changed();
    /* The best filter: 32-bit before 16-bit, list before mask, lower number. */
    int best_fifo = -1;
    unsigned best_rank = 0;
    unsigned best_fmi = 0;
    unsigned number[2] = {0, 0}; /* filter numbers are counted per FIFO */
    for (unsigned b = 0; b < BANKS; b++) {
        unsigned fifo = (can.ffa1r >> b) & 1u;
        unsigned first = number[fifo];
        number[fifo] += bank_filters(b);
        if (((can.fa1r >> b) & 1u) == 0u) {
            continue;
        }
        int k = bank_match(b, f);
        if (k < 0) {
            continue;
        }
        unsigned wide = (can.fs1r >> b) & 1u;
        unsigned list = (can.fm1r >> b) & 1u;
        unsigned rank = wide * 2u + list; /* higher is better; ties: the first found */
        if (best_fifo < 0 || rank > best_rank) {
            best_fifo = (int)fifo;
            best_rank = rank;
            best_fmi = first + (unsigned)k;
        }
    }
    if (best_fifo < 0) {
        return STM_CAN_FILTERED;
    }
    fifo_t *q = &can.fifo[best_fifo];
    rx_msg_t m = {0};
    m.rir = key32(f);
    m.rdtr = (f->dlc & 0xFu) | (best_fmi << 8);
    for (unsigned b = 0; b < 4u; b++) {
        m.rdlr |= (uint32_t)f->data[b] << (8u * b);
        m.rdhr |= (uint32_t)f->data[4u + b] << (8u * b);
    }
    if (q->count == 3u) {
        q->ovr = true;
        if ((can.mcr & MCR_RFLM) == 0u) {
            q->msg[2] = m; /* not locked: the last message stored is overwritten */
        }
    } else {
        q->msg[q->count++] = m;
        q->full = q->count == 3u;
    }
    stm_progress();
    return best_fifo;
}

/* ---- registers ------------------------------------------------------------- */

static bool in_init(void)
{
    return can.mode == STM_CAN_INIT;
}

static uint32_t tsr_value(void)
{
    uint32_t v = can.tsr_flags;
    int code = -1;
    for (int i = 2; i >= 0; i--) {
        if (!can.tx[i].pending) {
            v |= 1u << (26 + i); /* TMEx */
            code = i;
        }
    }
    return v | ((uint32_t)(code < 0 ? 0 : code) << 24);
}

static uint32_t rf_value(const fifo_t *q)
{
    return q->count | (q->full ? 8u : 0u) | (q->ovr ? 0x10u : 0u);
}

uint32_t bxcan_read(uint32_t off, bool peek)
{
    if (off >= 0x180u && off < 0x1B0u) {
        const mailbox_t *m = &can.tx[(off - 0x180u) / 0x10u];
        const uint32_t regs[4] = {m->tir | (m->pending ? 1u : 0u), m->tdtr, m->tdlr, m->tdhr};
        return regs[(off & 0xFu) / 4u];
    }
    if (off >= 0x1B0u && off < 0x1D0u) {
        unsigned f = (off - 0x1B0u) / 0x10u;
        const fifo_t *q = &can.fifo[f];
        if (q->count == 0u && !peek) {
            stm_violation("CAN: read of FIFO %u's output mailbox (offset 0x%03X) while it is empty",
                          f, (unsigned)off);
        }
        const rx_msg_t *m = &q->msg[0];
        const uint32_t regs[4] = {m->rir, m->rdtr, m->rdlr, m->rdhr};
        return regs[(off & 0xFu) / 4u];
    }
    if (off >= 0x240u && off < 0x240u + 8u * BANKS) {
        return can.fr[(off - 0x240u) / 8u][((off - 0x240u) / 4u) & 1u];
    }
    switch (off) {
    case 0x000u:
        return can.mcr;
    case 0x004u:
        if (!peek) {
            msr_tick();
        }
        return (can.mode == STM_CAN_INIT ? MSR_INAK : 0u) |
               (can.mode == STM_CAN_SLEEP ? MSR_SLAK : 0u) | can.msr_flags |
               (can.stuck ? 0u : (1u << 11)) /* RX: the bus level */;
    case 0x008u:
        return tsr_value();
    case 0x00Cu:
        return rf_value(&can.fifo[0]);
    case 0x010u:
        return rf_value(&can.fifo[1]);
    case 0x014u:
        return can.ier;
    case 0x018u:
        return esr_flags() | (can.lec << 4) | ((can.tec & 0xFFu) << 16) | (can.rec << 24);
    case 0x01Cu:
        if (!in_init() && !peek) {
            stm_violation("CAN_BTR read outside initialization mode");
        }
        return can.btr;
    case 0x200u:
        return can.fmr;
    case 0x204u:
        return can.fm1r;
    case 0x20Cu:
        return can.fs1r;
    case 0x214u:
        return can.ffa1r;
    case 0x21Cu:
        return can.fa1r;
    default:
        if (!peek) {
            stm_violation("CAN: read of reserved offset 0x%03X", (unsigned)off);
        }
        return 0;
    }
}

static void write_mailbox(unsigned i, unsigned reg, uint32_t v)
{
    mailbox_t *m = &can.tx[i];
    if (m->pending) {
        stm_violation("CAN: mailbox %u register %u written while not empty (TME%u = 0)", i, reg, i);
        return;
    }
    switch (reg) {
    case 0u:
        m->tir = v & ~1u;
        if ((v & 1u) != 0u) {
            m->pending = true;
            m->order = can.next_order++;
            can.tsr_flags &= ~(0xFFu << (8u * i)); /* a new request */
        }
        break;
    case 1u:
        m->tdtr = v & 0xFFFF010Fu;
        break;
    case 2u:
        m->tdlr = v;
        break;
    default:
        m->tdhr = v;
        break;
    }
}

/* A filter configuration register (FM1R, FS1R, FFA1R). */
static void write_filter_config(uint32_t *reg, const char *name, uint32_t v)
{
    if ((can.fmr & 1u) == 0u) {
        stm_violation("CAN_%s written while FINIT is clear (filter initialization mode needed)",
                      name);
        return;
    }
    if ((v & ~BANK_MASK) != 0u) {
        stm_violation("CAN_%s: reserved bits 31:14 written 0x%08X", name, (unsigned)v);
    }
    uint32_t changed = (v ^ *reg) & can.fa1r & BANK_MASK;
    if (changed != 0u) {
        stm_violation("CAN_%s: banks 0x%04X reconfigured while active (FACT set)", name,
                      (unsigned)changed);
    }
    *reg = v & BANK_MASK;
}

void bxcan_write(uint32_t off, uint32_t v)
{
    if (off >= 0x180u && off < 0x1B0u) {
        write_mailbox((off - 0x180u) / 0x10u, (off & 0xFu) / 4u, v);
        return;
    }
    if (off >= 0x1B0u && off < 0x1D0u) {
        stm_violation("CAN: write of receive mailbox register at 0x%03X (read-only)",
                      (unsigned)off);
        return;
    }
    if (off >= 0x240u && off < 0x240u + 8u * BANKS) {
        unsigned b = (off - 0x240u) / 8u;
        if ((can.fmr & 1u) == 0u && ((can.fa1r >> b) & 1u) != 0u) {
            stm_violation("CAN_F%uR%u written while bank %u is active and FINIT is clear", b,
                          ((off - 0x240u) / 4u & 1u) + 1u, b);
            return;
        }
        can.fr[b][((off - 0x240u) / 4u) & 1u] = v;
        return;
    }
    switch (off) {
    case 0x000u:
        if ((v & ~MCR_WRITABLE) != 0u) {
            stm_violation("CAN_MCR: reserved bits written 0x%08X", (unsigned)v);
        }
        if ((v & MCR_RESET) != 0u) {
            bxcan_reset(); /* master reset: back to sleep mode */
            return;
        }
        can.mcr = v & MCR_WRITABLE;
        request_mode();
        break;
    case 0x004u:
        can.msr_flags &= ~(v & 0x1Cu); /* ERRI, WKUI, SLAKI: write 1 to clear */
        break;
    case 0x008u:
        for (unsigned i = 0; i < 3u; i++) {
            uint32_t shift = 8u * i;
            if ((v & (1u << shift)) != 0u) {
                can.tsr_flags &= ~(0xFu << shift); /* RQCP clears TXOK, ALST, TERR too */
            }
            if ((v & (0x80u << shift)) != 0u && can.tx[i].pending) {
                can.tx[i].pending = false; /* ABRQ */
                can.tsr_flags = (can.tsr_flags & ~(0xFFu << shift)) | (1u << shift);
            }
        }
        break;
    case 0x00Cu:
    case 0x010u: {
        fifo_t *q = &can.fifo[(off - 0x00Cu) / 4u];
        if ((v & 8u) != 0u) {
            q->full = false;
        }
        if ((v & 0x10u) != 0u) {
            q->ovr = false;
        }
        if ((v & 0x20u) != 0u && q->count > 0u) {
            memmove(&q->msg[0], &q->msg[1], 2u * sizeof(q->msg[0])); /* RFOM */
            q->count--;
        }
        if ((v & ~0x38u) != 0u) {
            stm_violation("CAN_RF%uR: read-only or reserved bits written 0x%08X",
                          (unsigned)(off - 0x00Cu) / 4u, (unsigned)v);
        }
        break;
    }
    case 0x014u:
        can.ier = v & 0x00038F7Fu;
        break;
    case 0x018u:
        can.lec = (v >> 4) & 7u; /* only LEC is writable */
        break;
    case 0x01Cu:
        if (!in_init()) {
            stm_violation("CAN_BTR written outside initialization mode (0x%08X)", (unsigned)v);
            return;
        }
        if ((v & ~BTR_WRITABLE) != 0u) {
            stm_violation("CAN_BTR: reserved bits written 0x%08X", (unsigned)v);
        }
        can.btr = v & BTR_WRITABLE;
        break;
    case 0x200u:
        if ((v & ~1u) != (FMR_RESET & ~1u)) {
            stm_violation("CAN_FMR: reserved bits not kept at their reset value (0x%08X)",
                          (unsigned)v);
        }
        can.fmr = (FMR_RESET & ~1u) | (v & 1u);
        break;
    case 0x204u:
        write_filter_config(&can.fm1r, "FM1R", v);
        break;
    case 0x20Cu:
        write_filter_config(&can.fs1r, "FS1R", v);
        break;
    case 0x214u:
        write_filter_config(&can.ffa1r, "FFA1R", v);
        break;
    case 0x21Cu:
        if ((v & ~BANK_MASK) != 0u) {
            stm_violation("CAN_FA1R: reserved bits 31:14 written 0x%08X", (unsigned)v);
        }
        can.fa1r = v & BANK_MASK;
        break;
    default:
        stm_violation("CAN: write of reserved offset 0x%03X", (unsigned)off);
        break;
    }
}
