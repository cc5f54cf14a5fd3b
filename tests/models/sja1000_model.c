/*
 * sja1000_model.c - the SJA1000 in PeliCAN mode and the bus around it, at
 * register level (see sja1000_model.h; NXP SJA1000 data sheet, 6.4). The
 * numbers below are the data sheet's, on purpose not the driver's.
 */
#include "sja1000_model.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* PeliCAN addresses (data sheet, Table 3 "PeliCAN address allocation"). */
#define A_MOD 0u
#define A_CMR 1u
#define A_SR 2u
#define A_IR 3u
#define A_IER 4u
#define A_BTR0 6u
#define A_BTR1 7u
#define A_OCR 8u
#define A_EWLR 13u
#define A_RXERR 14u
#define A_TXERR 15u
#define A_BUF 16u /* 16..28: ACR/AMR (reset mode), TX buffer / RX window (operating) */
#define A_RMC 29u
#define A_RBSA 30u
#define A_CDR 31u

/* MOD (Table 7) */
#define MOD_RM 0x01u
#define MOD_LOM 0x02u
#define MOD_STM 0x04u
#define MOD_AFM 0x08u
#define MOD_SM 0x10u
/* CMR (Table 8) */
#define CMR_TR 0x01u
#define CMR_AT 0x02u
#define CMR_RRB 0x04u
#define CMR_CDO 0x08u
#define CMR_SRR 0x10u
/* SR (Table 9) */
#define SR_RBS 0x01u
#define SR_DOS 0x02u
#define SR_TBS 0x04u
#define SR_TCS 0x08u
#define SR_RS 0x10u
#define SR_TS 0x20u
#define SR_ES 0x40u
#define SR_BS 0x80u
/* IR and IER (Tables 10, 11) */
#define IR_RI 0x01u
#define IR_TI 0x02u
#define IR_EI 0x04u
#define IR_DOI 0x08u
#define IR_EPI 0x20u
/* CDR (Table 46): CAN mode, CBP, RXINTEN, clock off in reset mode only */
#define CDR_RESET_ONLY 0xE8u
#define CDR_PELICAN 0x80u

__attribute__((format(printf, 2, 3))) static void violation(sja_model_t *m, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->last_violation, sizeof m->last_violation, fmt, ap);
    va_end(ap);
    m->violations++;
    fprintf(stderr, "sja1000 model: %s\n", m->last_violation);
}

static bool in_reset(const sja_model_t *m)
{
    return (m->mod & MOD_RM) != 0u;
}

static bool pelican(const sja_model_t *m)
{
    return (m->cdr & CDR_PELICAN) != 0u;
}

static void irq(sja_model_t *m, uint8_t bit)
{
    if ((m->ier & bit) != 0u) {
        m->ir |= bit;
    }
}

/* ES, BS and error passive from the counters; EI and EPI on a change. */
static void update_status(sja_model_t *m)
{
    if (in_reset(m)) {
        return; /* a change forced in reset mode shows when it is left (6.4.11) */
    }
    bool es = m->bs || m->rxerr >= m->ewlr || m->txerr >= m->ewlr;
    bool passive = !m->bs && (m->rxerr > 127u || m->txerr > 127u);
    if (es != m->es) {
        m->es = es;
        irq(m, IR_EI);
    }
    if (passive != m->passive) {
        m->passive = passive;
        irq(m, IR_EPI);
    }
}

static void enter_reset(sja_model_t *m, bool by_cpu)
{
    m->mod |= MOD_RM;
    m->tx_pending = false; /* the transmission is aborted; TCS keeps its value */
    if (!m->qemu) {
        m->rmc = 0; /* the FIFO is cleared, RBSA kept */
        m->rx_bytes = 0;
    }
    m->dos = false;
    m->ir = 0;
    if (by_cpu) {
        m->reset_entries++;
    }
}

static void leave_reset(sja_model_t *m)
{
    m->mod = (uint8_t)(m->mod & ~MOD_RM);
    if (m->bs) {
        m->idle_seen = 0; /* the bus-off recovery starts now */
    }
    update_status(m);
}

void sja_model_new(sja_model_t *m)
{
    memset(m, 0, sizeof *m);
    /* Hardware reset values (Table 5): BasicCAN, reset mode, SR 0x3C. */
    m->mod = MOD_RM;
    m->ewlr = 96;
    m->tcs = true;
    /* Undefined after a hardware reset ("X"): a pattern, so that a driver
     * relying on them is seen. */
    m->btr0 = 0x5A;
    m->btr1 = 0xA5;
    m->ocr = 0x33;
    for (unsigned i = 0; i < 4u; i++) {
        m->acr[i] = (uint8_t)(0x11u * (i + 1u));
        m->amr[i] = (uint8_t)(0x0Fu << i);
    }
    for (unsigned i = 0; i < sizeof m->fifo; i++) {
        m->fifo[i] = (uint8_t)(i * 29u + 7u);
    }
}

static uint8_t status(const sja_model_t *m)
{
    uint8_t sr = 0;
    sr |= m->rmc > 0u ? SR_RBS : 0u;
    sr |= m->dos ? SR_DOS : 0u;
    sr |= m->tx_pending ? 0u : SR_TBS;
    sr |= m->tcs ? SR_TCS : 0u;
    sr |= (in_reset(m) || m->bs) ? (uint8_t)(SR_RS | SR_TS) : 0u;
    sr |= m->es ? SR_ES : 0u;
    sr |= m->bs ? SR_BS : 0u;
    return sr;
}

/* Bytes the FIFO's message at offset `at` takes. */
static uint8_t msg_len(const sja_model_t *m, unsigned at)
{
    uint8_t fi = m->fifo[at % 64u];
    unsigned n = (fi & 0x40u) != 0u ? 0u : (fi & 0x0Fu);
    n = n > 8u && !m->qemu ? 8u : n; /* QEMU takes the field as it is */
    return (uint8_t)(((fi & 0x80u) != 0u ? 5u : 3u) + n);
}

uint8_t sja_model_read(void *ctx, uint8_t reg)
{
    sja_model_t *m = ctx;
    m->reads++;
    if (m->absent) {
        return 0xFF;
    }
    if (reg > 31u) {
        violation(m, "read of address %u: the accessor's range is 0..31", reg);
        return 0xFF;
    }
    if (!pelican(m)) {
        switch (reg) {
        case A_MOD: /* BasicCAN control register: RR is bit 0 */
            return (uint8_t)((m->mod & MOD_RM) | m->cr_bits);
        case A_SR:
            return status(m);
        case A_CDR:
            return m->cdr;
        default: /* a BasicCAN register: not modelled */
            return reg == A_BUF && m->basic_echo ? m->basic16 : 0xFF;
        }
    }
    switch (reg) {
    case A_MOD:
        return m->mod & 0x1Fu;
    case A_CMR:
        return 0xFF;
    case A_SR:
        return status(m);
    case A_IR: {
        uint8_t v = m->ir;
        if ((m->ier & IR_RI) != 0u && m->rmc > 0u) {
            v |= IR_RI;
        }
        m->ir = 0;
        return v;
    }
    case A_IER:
        return m->ier;
    case A_BTR0:
        return m->btr0;
    case A_BTR1:
        return m->btr1;
    case A_OCR:
        return m->ocr;
    case A_EWLR:
        return m->ewlr;
    case A_RXERR:
        return m->rxerr;
    case A_TXERR:
        return m->txerr;
    case A_RMC:
        return m->qemu ? 0xFFu : m->rmc;
    case A_RBSA:
        return m->qemu ? 0xFFu : m->rbsa;
    case A_CDR:
        return m->cdr;
    default:
        break;
    }
    if (reg >= A_BUF && reg <= 28u) {
        unsigned k = reg - A_BUF;
        if (in_reset(m)) {
            uint8_t v = k < 4u ? m->acr[k] : k < 8u ? m->amr[k - 4u] : 0u;
            return k == 0u && m->acr_broken ? (uint8_t)(v ^ 1u) : v;
        }
        if (m->rmc == 0u) {
            violation(m, "RX buffer (address %u) read with RBS 0", reg);
        }
        return m->fifo[(m->rbsa + k) % 64u];
    }
    return 0; /* reserved, test register, ALC, ECC */
}

static void command(sja_model_t *m, uint8_t v)
{
    if ((v & (CMR_TR | CMR_SRR)) != 0u) {
        if (in_reset(m)) {
            violation(m, "CMR transmission request in reset mode");
        } else if (m->tx_pending) {
            violation(m, "CMR transmission request while one is pending (TBS 0)");
        } else {
            m->tx_pending = true;
            m->single_shot = (v & CMR_AT) != 0u;
            m->tcs = false;
        }
    } else if ((v & CMR_AT) != 0u && m->tx_pending) {
        m->tx_pending = false; /* not yet on the bus in this model: cancelled */
        m->aborts++;
        irq(m, IR_TI);
    }
    if ((v & CMR_RRB) != 0u) {
        if (m->rmc == 0u) {
            violation(m, "CMR release receive buffer with the FIFO empty");
        } else {
            uint8_t len = msg_len(m, m->rbsa);
            m->rbsa = (uint8_t)((m->rbsa + len) % 64u);
            m->rx_bytes = (uint8_t)(m->rx_bytes - len);
            m->rmc--;
        }
    }
    if ((v & CMR_CDO) != 0u) {
        m->dos = false;
    }
}

static void reset_only(sja_model_t *m, uint8_t reg, uint8_t *r, uint8_t v)
{
    if (!in_reset(m)) {
        violation(m, "address %u written in operating mode (reset mode only)", reg);
        return;
    }
    *r = v;
}

static void write_mod(sja_model_t *m, uint8_t v)
{
    const uint8_t cfg = MOD_LOM | MOD_STM | MOD_AFM;
    if ((v & MOD_SM) != 0u) {
        violation(m, "MOD.SM (sleep) set: not modelled");
    }
    if (in_reset(m)) {
        m->mod = (uint8_t)((m->mod & ~cfg) | (v & cfg));
    } else if (((m->mod ^ v) & cfg) != 0u) {
        violation(m, "MOD LOM/STM/AFM changed in operating mode (reset mode only)");
    }
    bool change = ((v & MOD_RM) != 0u) != in_reset(m);
    if (change && m->mode_lag > 0u) {
        m->mode_lag--; /* not yet */
    } else if ((v & MOD_RM) != 0u && !in_reset(m) && !m->stuck_operating) {
        enter_reset(m, true);
    } else if ((v & MOD_RM) == 0u && in_reset(m) && !m->stuck_reset) {
        leave_reset(m);
    }
}

static void write_cdr(sja_model_t *m, uint8_t v)
{
    v &= 0xEFu; /* CDR.4 reserved */
    if (m->basic_only) {
        v &= (uint8_t)~CDR_PELICAN;
    }
    if (in_reset(m)) {
        m->cdr = v;
        return;
    }
    if (((m->cdr ^ v) & CDR_RESET_ONLY) != 0u) {
        violation(m, "CDR mode bits changed in operating mode (reset mode only)");
    }
    m->cdr = (uint8_t)((m->cdr & CDR_RESET_ONLY) | (v & 0x07u));
}

void sja_model_write(void *ctx, uint8_t reg, uint8_t v)
{
    sja_model_t *m = ctx;
    m->writes++;
    if (m->absent) {
        return;
    }
    if (reg > 31u) {
        violation(m, "write of address %u: the accessor's range is 0..31", reg);
        return;
    }
    if (!pelican(m)) {
        if (reg == A_MOD) {
            m->cr_bits = v & 0x1Eu;
            write_mod(m, v & MOD_RM);
        } else if (reg == A_CDR) {
            write_cdr(m, v);
        } else if (reg == A_BUF && m->basic_echo) {
            m->basic16 = v;
            violation(m, "address %u written in BasicCAN mode (CDR.7 0)", reg);
        } else {
            violation(m, "address %u written in BasicCAN mode (CDR.7 0)", reg);
        }
        return;
    }
    switch (reg) {
    case A_MOD:
        write_mod(m, v);
        return;
    case A_CMR:
        command(m, v);
        return;
    case A_SR:
    case A_IR:
    case A_RMC:
        violation(m, "read-only register %u written", reg);
        return;
    case A_IER:
        m->ier = v;
        return;
    case A_BTR0:
        reset_only(m, reg, &m->btr0, v);
        return;
    case A_BTR1:
        reset_only(m, reg, &m->btr1, v);
        return;
    case A_OCR:
        reset_only(m, reg, &m->ocr, v);
        return;
    case A_EWLR:
        reset_only(m, reg, &m->ewlr, v);
        return;
    case A_RXERR:
        if (!m->bs) { /* writing it has no effect while bus-off (6.4.11) */
            reset_only(m, reg, &m->rxerr, v);
        }
        return;
    case A_TXERR:
        reset_only(m, reg, &m->txerr, v);
        if (in_reset(m) && m->bs && v < 255u) {
            m->bs = false;
            violation(m, "TXERR written during bus-off: recovery without 128 x 11 recessive bits");
        }
        return;
    case A_RBSA:
        reset_only(m, reg, &m->rbsa, (uint8_t)(v & 0x3Fu));
        return;
    case A_CDR:
        write_cdr(m, v);
        return;
    default:
        break;
    }
    if (reg >= A_BUF && reg <= 28u) {
        unsigned k = reg - A_BUF;
        if (in_reset(m)) {
            if (k < 4u) {
                m->acr[k] = v;
            } else if (k < 8u) {
                m->amr[k - 4u] = v;
            }
        } else if (m->tx_pending) {
            violation(m, "TX buffer (address %u) written while locked (TBS 0): byte lost", reg);
        } else {
            m->txb[k] = v;
        }
    }
    /* reserved, test register, ALC, ECC: nothing */
}

const sja1000_io_t sja_model_io = {sja_model_read, sja_model_write};

static bool match(uint8_t bits, uint8_t code, uint8_t mask, uint8_t which)
{
    return ((uint8_t)(bits ^ code) & (uint8_t)~mask & which) == 0u;
}

bool sja_model_accepts(const sja_model_t *m, uint32_t id, bool ext, bool rtr, uint8_t dlc,
                       const uint8_t *data)
{
    const uint8_t *c = m->acr;
    const uint8_t *k = m->amr;
    uint8_t n = rtr ? 0u : dlc; /* data bytes the message has */
    if (!ext) {
        uint8_t b0 = (uint8_t)(id >> 3);
        uint8_t b1 = (uint8_t)(((id & 7u) << 5) | (rtr ? 0x10u : 0u));
        if ((m->mod & MOD_AFM) != 0u) { /* single filter, standard frame (Fig. 9) */
            return match(b0, c[0], k[0], 0xFF) && match(b1, c[1], k[1], 0xF0) &&
                   (n < 1u || match(data[0], c[2], k[2], 0xFF)) &&
                   (n < 2u || match(data[1], c[3], k[3], 0xFF));
        }
        /* dual filter, standard frame (Fig. 11): filter 1 with data byte 1 */
        bool f1 = match(b0, c[0], k[0], 0xFF) && match(b1, c[1], k[1], 0xF0) &&
                  (n < 1u || (match((uint8_t)(data[0] >> 4), c[1], k[1], 0x0F) &&
                              match(data[0], c[3], k[3], 0x0F)));
        bool f2 = match(b0, c[2], k[2], 0xFF) && match(b1, c[3], k[3], 0xF0);
        return f1 || f2;
    }
    uint8_t e0 = (uint8_t)(id >> 21);
    uint8_t e1 = (uint8_t)(id >> 13);
    uint8_t e2 = (uint8_t)(id >> 5);
    uint8_t e3 = (uint8_t)(((id & 0x1Fu) << 3) | (rtr ? 0x04u : 0u));
    if ((m->mod & MOD_AFM) != 0u) { /* single filter, extended frame (Fig. 10) */
        return match(e0, c[0], k[0], 0xFF) && match(e1, c[1], k[1], 0xFF) &&
               match(e2, c[2], k[2], 0xFF) && match(e3, c[3], k[3], 0xFC);
    }
    /* dual filter, extended frame (Fig. 12): ID.28..13 in each */
    return (match(e0, c[0], k[0], 0xFF) && match(e1, c[1], k[1], 0xFF)) ||
           (match(e0, c[2], k[2], 0xFF) && match(e1, c[3], k[3], 0xFF));
}

static void fifo_put(sja_model_t *m, uint8_t b)
{
    m->fifo[(m->rbsa + m->rx_bytes) % 64u] = b;
    m->rx_bytes++;
}

bool sja_model_rx(sja_model_t *m, uint32_t id, bool ext, bool rtr, uint8_t dlc, const uint8_t *data)
{
    if (m->absent || !pelican(m) || in_reset(m) || m->bs) {
        return false; /* not on the bus */
    }
    if (!sja_model_accepts(m, id, ext, rtr, dlc, data)) {
        return false;
    }
    unsigned n = rtr && !m->qemu ? 0u : (dlc > 8u ? 8u : dlc);
    unsigned len = (ext ? 5u : 3u) + n;
    if (m->rx_bytes + len > sizeof m->fifo) {
        m->lost++;
        if (!m->dos) {
            m->dos = true;
            irq(m, IR_DOI);
        }
        return false;
    }
    fifo_put(m, (uint8_t)((ext ? 0x80u : 0u) | (rtr ? 0x40u : 0u) | (dlc & 0x0Fu)));
    if (ext) {
        fifo_put(m, (uint8_t)(id >> 21));
        fifo_put(m, (uint8_t)(id >> 13));
        fifo_put(m, (uint8_t)(id >> 5));
        fifo_put(m, (uint8_t)(((id & 0x1Fu) << 3) | (rtr ? 0x04u : 0u)));
    } else {
        fifo_put(m, (uint8_t)(id >> 3));
        fifo_put(m, (uint8_t)(((id & 7u) << 5) | (rtr ? 0x10u : 0u)));
    }
    for (unsigned i = 0; i < n; i++) {
        fifo_put(m, data != NULL ? data[i] : 0u);
    }
    m->rmc++;
    if (m->rxerr > 127u) { /* a successful reception (ISO 11898-1) */
        m->rxerr = 120;
    } else if (m->rxerr > 0u) {
        m->rxerr--;
    }
    update_status(m);
    return true;
}

bool sja_model_bus(sja_model_t *m)
{
    if (!m->tx_pending || in_reset(m) || m->bs) {
        return false;
    }
    if (m->no_ack) {
        /* ACK error: + 8, but not for an error-passive transmitter */
        if (m->txerr < 128u) {
            m->txerr = (uint8_t)(m->txerr + 8u);
        }
        if (m->single_shot) {
            m->tx_pending = false;
            irq(m, IR_TI);
        }
        update_status(m);
        return false;
    }
    if (m->nsent >= SJA_MODEL_SENT_MAX) {
        violation(m, "more than %u frames sent: the test's record is full", SJA_MODEL_SENT_MAX);
        return false;
    }
    sja_model_sent_t *s = &m->sent[m->nsent++];
    memset(s, 0, sizeof *s);
    uint8_t fi = m->txb[0];
    s->ext = (fi & 0x80u) != 0u;
    s->rtr = (fi & 0x40u) != 0u;
    s->dlc = fi & 0x0Fu;
    unsigned d0;
    if (s->ext) {
        s->id = ((uint32_t)m->txb[1] << 21) | ((uint32_t)m->txb[2] << 13) |
                ((uint32_t)m->txb[3] << 5) | (uint32_t)(m->txb[4] >> 3);
        d0 = 5;
    } else {
        s->id = ((uint32_t)m->txb[1] << 3) | (uint32_t)(m->txb[2] >> 5);
        d0 = 3;
    }
    unsigned n = s->rtr ? 0u : (s->dlc > 8u ? 8u : s->dlc);
    for (unsigned i = 0; i < n && d0 + i < sizeof m->txb; i++) {
        s->data[i] = m->txb[d0 + i];
    }
    m->tx_pending = false;
    m->tcs = true;
    if (m->txerr > 0u) {
        m->txerr--;
    }
    irq(m, IR_TI);
    update_status(m);
    return true;
}

const sja_model_sent_t *sja_model_next(sja_model_t *m)
{
    return m->taken < m->nsent ? &m->sent[m->taken++] : NULL;
}

void sja_model_errors(sja_model_t *m, unsigned rx, unsigned tx)
{
    if (in_reset(m) || m->bs) {
        return; /* off the bus: no errors counted */
    }
    if (tx > 255u) {
        /* bus-off (SR notes 1): RM set, TXERR 127, RXERR 0, EI */
        enter_reset(m, false);
        m->bs = true;
        m->txerr = 127;
        m->rxerr = 0;
        m->es = true;
        m->passive = false;
        irq(m, IR_EI);
        return;
    }
    m->rxerr = (uint8_t)(rx > 255u ? 255u : rx);
    m->txerr = (uint8_t)tx;
    update_status(m);
}

void sja_model_idle(sja_model_t *m, unsigned n)
{
    while (n-- > 0u) {
        if (!m->bs || in_reset(m)) {
            return; /* only the bus-off recovery counts bus-free time here */
        }
        m->idle_seen++;
        if (m->idle_seen < 128u) {
            m->txerr = (uint8_t)(127u - m->idle_seen);
            continue;
        }
        m->bs = false;
        m->txerr = 0;
        m->rxerr = 0;
        update_status(m); /* ES 0: EI */
    }
}

unsigned sja_model_take_violations(sja_model_t *m)
{
    unsigned v = m->violations;
    m->violations = 0;
    return v;
}
