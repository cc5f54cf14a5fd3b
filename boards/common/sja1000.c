/*
 * sja1000.c - see sja1000.h.
 *
 * The transmit queue holds the frame in the transmit buffer too, at its
 * head, until the status register shows the buffer released (TBS): a
 * frame whose transmission a trip through reset mode (a new bit rate or
 * filter, a bus-off) cut short is written again rather than lost. At worst
 * it goes out twice, as after any CAN error.
 */
#include "sja1000.h"

/* Polls of the mode register before a mode change counts as refused (the
 * data sheet's controller changes mode within one clock). */
#define MODE_TRIES 64u
/* The most frames the 64-byte RX FIFO can hold (3-byte frames: no data). */
#define RX_FIFO_FRAMES 21u
#define TIME_QUANTA_MIN 8u
#define TIME_QUANTA_MAX 25u
/* TSEG2 is (q + 4) / 8 <= 3 quanta, or q - 17 when TSEG1 is full: within
 * the 8 its field holds for every q up to TIME_QUANTA_MAX. */
#if TIME_QUANTA_MAX - 17u > 8u
#error "TSEG2 could exceed 8 quanta"
#endif
#define ERR_PASSIVE 128u

static uint8_t rd(const sja1000_t *c, uint8_t reg)
{
    return c->io->read(c->ctx, reg);
}

static void wr(const sja1000_t *c, uint8_t reg, uint8_t v)
{
    c->io->write(c->ctx, reg, v);
}

/* Mode register to mode (dual filter: AFM clear); true once the controller
 * shows it. */
static bool set_mode(const sja1000_t *c, uint8_t mode)
{
    for (unsigned i = 0; i < MODE_TRIES; i++) {
        wr(c, SJA_MOD, mode);
        if ((rd(c, SJA_MOD) & SJA_MOD_RM) == (mode & SJA_MOD_RM)) {
            return true;
        }
    }
    return false;
}

bool sja1000_timing(uint32_t clock_hz, uint16_t kbps, uint8_t *btr0, uint8_t *btr1)
{
    uint32_t bps = (uint32_t)kbps * 1000u;
    uint32_t best_q = 0;
    uint32_t best_brp = 0;
    uint32_t best_tseg2 = 0;
    uint32_t best_err = UINT32_MAX;
    for (uint32_t q = TIME_QUANTA_MAX; q >= TIME_QUANTA_MIN && bps != 0u; q--) {
        uint32_t per_quantum = 2u * bps * q; /* fosc / (BRP + 1) */
        if (clock_hz % per_quantum != 0u) {
            continue;
        }
        uint32_t brp = clock_hz / per_quantum;
        uint32_t tseg2 = (q + 4u) / 8u; /* 12.5 % of the bit, rounded */
        if (q - 1u - tseg2 > 16u) {
            tseg2 = q - 17u; /* TSEG1 holds at most 16 quanta */
        }
        if (brp < 1u || brp > 64u) {
            continue;
        }
        /* Sample point (after SYNC and TSEG1) in permille, its distance to 875. */
        uint32_t sp = (q - tseg2) * 1000u / q;
        uint32_t err = sp > 875u ? sp - 875u : 875u - sp;
        if (err < best_err) { /* from the most quanta down: ties keep more */
            best_err = err;
            best_q = q;
            best_brp = brp;
            best_tseg2 = tseg2;
        }
    }
    if (best_q == 0u) {
        return false;
    }
    uint32_t sjw = best_tseg2 < 4u ? best_tseg2 : 4u;
    *btr0 = (uint8_t)(((sjw - 1u) << 6) | (best_brp - 1u));
    *btr1 = (uint8_t)(((best_tseg2 - 1u) << 4) | (best_q - 2u - best_tseg2));
    return true;
}

/* ---- acceptance filter -------------------------------------------------- */

static unsigned bits11(uint32_t m)
{
    unsigned n = 0;
    for (; m != 0u; m &= m - 1u) {
        n++;
    }
    return n;
}

/* What a code/mask pair over the IDs of one group accepts: 2^(mask bits). */
static uint32_t cost(uint32_t mask, bool used)
{
    return used ? 1u << bits11(mask) : 0u;
}

/* One dual-mode filter in its registers: code and mask over the 11 ID
 * bits, the RTR bit never compared. Filter 1 also compares the first data
 * byte (ACR1/ACR3 low nibbles): masked out. */
static void put_filter(sja1000_t *c, unsigned k, uint16_t code, uint16_t mask)
{
    unsigned r = 2u * k; /* filter 1: ACR0/ACR1 (AMR0/AMR1), filter 2: ACR2/ACR3 */
    c->acr[r] = (uint8_t)(code >> 3);
    c->amr[r] = (uint8_t)(mask >> 3);
    c->acr[r + 1u] = (uint8_t)((code & 7u) << 5);
    c->amr[r + 1u] = (uint8_t)(((mask & 7u) << 5) | 0x1Fu);
}

/* Every bit "don't care": the filter passes every frame. */
static void open_filter(sja1000_t *c)
{
    for (unsigned i = 0; i < 4u; i++) {
        c->acr[i] = 0x00u;
        c->amr[i] = 0xFFu;
    }
}

/*
 * Two code/mask pairs covering the distinct IDs u[0..m-1] with as few
 * other IDs as they can: every split into two groups when there are few
 * (u[0] stays in the first, so each split is tried once); else the ID
 * farthest from u[0] (most bits apart) starts the second group, and each
 * other ID goes to the group whose mask it widens least.
 */
static void choose_filters(sja1000_t *c, const uint16_t *u, unsigned m)
{
    uint16_t code[2] = {0, 0};
    uint16_t mask[2] = {0, 0};
    uint32_t best = UINT32_MAX;
    bool exact = m <= SJA1000_EXACT_IDS;
    uint32_t splits = exact ? 1u << (m - 1u) : 1u;
    uint16_t far = u[0];
    for (unsigned i = 1; i < m && !exact; i++) {
        far = bits11((uint32_t)(u[i] ^ u[0])) > bits11((uint32_t)(far ^ u[0])) ? u[i] : far;
    }
    for (uint32_t s = 0; s < splits; s++) {
        uint16_t mk[2] = {0, 0};
        uint16_t first[2] = {u[0], far};
        bool used = !exact; /* the second group has an ID */
        for (unsigned i = 1; i < m; i++) {
            unsigned g;
            if (exact) {
                g = (s >> (i - 1u)) & 1u;
            } else { /* greedy: where the mask grows least */
                g = bits11((uint32_t)(mk[1] | (u[i] ^ first[1]))) <
                            bits11((uint32_t)(mk[0] | (u[i] ^ first[0])))
                        ? 1u
                        : 0u;
            }
            if (g == 1u && !used) {
                used = true;
                first[1] = u[i];
            }
            mk[g] = (uint16_t)(mk[g] | (u[i] ^ first[g]));
        }
        /* One group (exact choice only): the second filter is u[0] alone,
         * far in that choice, which the first passes already. */
        uint32_t total = cost(mk[0], true) + cost(mk[1], used);
        if (total < best) {
            best = total;
            code[0] = first[0];
            code[1] = first[1];
            mask[0] = mk[0];
            mask[1] = mk[1];
        }
    }
    put_filter(c, 0, code[0], mask[0]);
    put_filter(c, 1, code[1], mask[1]);
}

/* The filter registers, in reset mode. */
static void write_filter(const sja1000_t *c)
{
    for (uint8_t i = 0; i < 4u; i++) {
        wr(c, (uint8_t)(SJA_ACR0 + i), c->acr[i]);
        wr(c, (uint8_t)(SJA_AMR0 + i), c->amr[i]);
    }
}

static bool listed(const sja1000_t *c, uint16_t id, bool rtr)
{
    for (unsigned k = 0; k < c->nids; k++) {
        if (c->ids[k].id == id && c->ids[k].rtr == rtr) {
            return true;
        }
    }
    return false;
}

/* ---- modes ------------------------------------------------------------- */

static void tx_released(sja1000_t *c, uint8_t sr);
static void kick(sja1000_t *c);

/* Reset mode, write what reset mode guards, back to operating mode. A
 * frame cut short in the transmit buffer is written again by kick(). */
static bool reprogram(sja1000_t *c, uint8_t btr0, uint8_t btr1)
{
    tx_released(c, rd(c, SJA_SR)); /* a frame sent already is not sent again */
    if (!set_mode(c, SJA_MOD_RM)) {
        return false;
    }
    wr(c, SJA_BTR0, btr0);
    wr(c, SJA_BTR1, btr1);
    write_filter(c);
    c->tx_busy = false;
    return set_mode(c, 0u);
}

bool sja1000_init(sja1000_t *c, const sja1000_io_t *io, void *ctx, uint32_t clock_hz, uint16_t kbps)
{
    *c = (sja1000_t){
        .io = io, .ctx = ctx, .clock_hz = clock_hz, .kbps = kbps, .state = (uint8_t)CO_CAN_ACTIVE};
    uint8_t btr0;
    uint8_t btr1;
    if (!set_mode(c, SJA_MOD_RM) || !sja1000_timing(clock_hz, kbps, &btr0, &btr1)) {
        return false;
    }
    wr(c, SJA_CDR, SJA_CDR_PELICAN | SJA_CDR_CLKOFF);
    wr(c, SJA_IER, 0u);
    /* A controller answers: PeliCAN mode taken, and the acceptance code
     * register (reset mode) holds what is written to it. */
    wr(c, SJA_ACR0, 0x5Au);
    if ((rd(c, SJA_CDR) & SJA_CDR_PELICAN) == 0u || rd(c, SJA_ACR0) != 0x5Au) {
        return false;
    }
    /* RMC counts at most the 21 messages the FIFO holds (none in reset
     * mode). QEMU's model has no RMC (nor RBSA): it reads 0xFF there, and
     * it is the model that stores a remote frame's data bytes
     * (sja1000_receive). No register shows its FIFO's position, so this
     * is the one check. */
    c->rtr_skews = rd(c, SJA_RMC) == 0xFFu;
    wr(c, SJA_OCR, SJA_OCR_NORMAL);
    open_filter(c);
    if (!reprogram(c, btr0, btr1)) {
        return false;
    }
    wr(c, SJA_IER, SJA_IR_RI | SJA_IR_TI | SJA_IR_EI | SJA_IR_DOI | SJA_IR_EPI);
    (void)rd(c, SJA_IR); /* nothing left over from before */
    return true;
}

/* A new filter into the controller once its RX FIFO is empty: reset mode
 * would empty it, losing frames received on IDs both lists hold. Until
 * then the software check holds the new list already. */
static void apply_filter(sja1000_t *c)
{
    uint8_t btr0;
    uint8_t btr1;
    if (c->filter_pending && (rd(c, SJA_SR) & SJA_SR_RBS) == 0u &&
        sja1000_timing(c->clock_hz, c->kbps, &btr0, &btr1)) { /* not after a refused init */
        c->filter_pending = !reprogram(c, btr0, btr1);
    }
}

bool sja1000_set_bitrate(sja1000_t *c, uint16_t kbps)
{
    uint8_t btr0;
    uint8_t btr1;
    if (!sja1000_timing(c->clock_hz, kbps, &btr0, &btr1)) {
        return false;
    }
    if (!reprogram(c, btr0, btr1)) {
        return false;
    }
    c->kbps = kbps;
    return true;
}

void sja1000_set_filter(sja1000_t *c, const co_rx_id_t *ids, unsigned n)
{
    co_rx_id_t list[SJA1000_IDS_MAX];
    unsigned m = 0;
    bool open = false;
    for (unsigned i = 0; i < n && !open; i++) {
        bool dup = false;
        for (unsigned k = 0; k < m; k++) {
            dup = dup || (list[k].id == ids[i].id && list[k].rtr == ids[i].rtr);
        }
        if (!dup) {
            open = m == SJA1000_IDS_MAX;
            if (!open) {
                list[m++] = ids[i];
            }
        }
    }
    bool filtered = !open && m > 0u;
    bool same = c->filtered == filtered && (!filtered || c->nids == m);
    for (unsigned k = 0; same && filtered && k < m; k++) {
        same = listed(c, list[k].id, list[k].rtr);
    }
    if (!same) {
        c->filtered = filtered;
        c->nids = (uint8_t)(filtered ? m : 0u);
        uint16_t u[SJA1000_IDS_MAX];
        unsigned nu = 0;
        for (unsigned k = 0; k < c->nids; k++) { /* the IDs without their RTR kind */
            bool dup = false;
            for (unsigned j = 0; j < nu; j++) {
                dup = dup || u[j] == list[k].id;
            }
            if (!dup) {
                u[nu++] = list[k].id;
            }
            c->ids[k] = list[k];
        }
        if (nu == 0u) {
            open_filter(c);
        } else {
            choose_filters(c, u, nu);
        }
        c->filter_pending = true;
    }
    apply_filter(c);
    kick(c);
}

/* ---- transmit ---------------------------------------------------------- */

/* The head of the queue into the transmit buffer when it is free; the head
 * leaves the queue once the buffer is released after it. */
static void tx_released(sja1000_t *c, uint8_t sr)
{
    if (c->tx_busy && (sr & SJA_SR_TBS) != 0u) {
        c->tx_busy = false;
        c->tx_head = (uint8_t)((c->tx_head + 1u) % SJA1000_TXQ_LEN);
        c->tx_len--;
    }
}

static void kick(sja1000_t *c)
{
    uint8_t sr = rd(c, SJA_SR);
    tx_released(c, sr);
    if ((sr & SJA_SR_TBS) == 0u || c->tx_busy || c->tx_len == 0u ||
        c->state == (uint8_t)CO_CAN_BUSOFF) {
        return;
    }
    const co_frame_t *f = &c->txq[c->tx_head];
    uint8_t dlc = f->dlc <= 8u ? f->dlc : 8u;
    wr(c, SJA_FRAME, (uint8_t)((f->rtr ? SJA_FI_RTR : 0u) | dlc));
    wr(c, SJA_FRAME + 1u, (uint8_t)(f->id >> 3));
    wr(c, SJA_FRAME + 2u, (uint8_t)((f->id & 7u) << 5));
    for (uint8_t i = 0; i < dlc && !f->rtr; i++) {
        wr(c, (uint8_t)(SJA_FRAME + 3u + i), f->data[i]);
    }
    wr(c, SJA_CMR, SJA_CMR_TR);
    c->tx_busy = true;
}

bool sja1000_send(sja1000_t *c, const co_frame_t *f)
{
    if (c->tx_len == SJA1000_TXQ_LEN || c->state == (uint8_t)CO_CAN_BUSOFF) {
        return false;
    }
    c->txq[(c->tx_head + c->tx_len) % SJA1000_TXQ_LEN] = *f;
    c->tx_len++;
    return true;
}

/* ---- receive ----------------------------------------------------------- */

bool sja1000_receive(sja1000_t *c, co_frame_t *f)
{
    for (unsigned n = 0; n < RX_FIFO_FRAMES; n++) {
        if ((rd(c, SJA_SR) & SJA_SR_RBS) == 0u) {
            return false;
        }
        uint8_t fi = rd(c, SJA_FRAME);
        bool ok = (fi & SJA_FI_FF) == 0u && !c->out_of_step;
        if (c->out_of_step) {
            c->unread++; /* what would be read is not this frame */
        } else if (ok) {
            f->id = (uint16_t)(((uint16_t)rd(c, SJA_FRAME + 1u) << 3) |
                               (rd(c, SJA_FRAME + 2u) >> 5));
            f->rtr = (fi & SJA_FI_RTR) != 0u;
            f->dlc = (uint8_t)((fi & 0x0Fu) <= 8u ? (fi & 0x0Fu) : 8u);
            for (uint8_t i = 0; i < f->dlc && !f->rtr; i++) {
                f->data[i] = rd(c, (uint8_t)(SJA_FRAME + 3u + i));
            }
            ok = !c->filtered || listed(c, f->id, f->rtr);
            if (!ok) {
                c->filtered_out++;
            }
        }
        wr(c, SJA_CMR, SJA_CMR_RRB);
        /* After this release the FIFO is read from inside the remote
         * frame's data bytes (extended ones too): this frame is whole. */
        c->out_of_step = c->out_of_step ||
                         (c->rtr_skews && (fi & SJA_FI_RTR) != 0u && (fi & 0x0Fu) != 0u);
        if (ok) {
            return true;
        }
    }
    return false;
}

/* ---- state ------------------------------------------------------------- */

co_can_state_t sja1000_service(sja1000_t *c)
{
    (void)rd(c, SJA_IR); /* releases the interrupt line */
    uint8_t sr = rd(c, SJA_SR);
    if ((sr & SJA_SR_DOS) != 0u) {
        c->overruns++;
        wr(c, SJA_CMR, SJA_CMR_CDO);
    }
    co_can_state_t s = CO_CAN_ACTIVE;
    if ((sr & SJA_SR_BS) != 0u) {
        s = CO_CAN_BUSOFF;
        /* The controller went to reset mode by itself: leave it, and the
         * SJA1000 comes back after 128 x 11 recessive bits. */
        if ((rd(c, SJA_MOD) & SJA_MOD_RM) != 0u) {
            c->tx_busy = false;
            (void)set_mode(c, 0u);
            c->restarts++;
        }
    } else if (rd(c, SJA_TXERR) >= ERR_PASSIVE || rd(c, SJA_RXERR) >= ERR_PASSIVE) {
        s = CO_CAN_PASSIVE;
    } else if ((sr & SJA_SR_ES) != 0u) {
        s = CO_CAN_WARNING;
    }
    c->state = (uint8_t)s;
    apply_filter(c);
    kick(c);
    return s;
}
