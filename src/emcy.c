/*
 * emcy.c - EMCY producer, error table and history. See co_emcy.h.
 */
#include "co_emcy.h"

#include <string.h>

#include "co_node.h"

#if CO_EMCY_HIST_MAX > 0
static void record(co_emcy_t *em, uint16_t code, const uint8_t msef[5])
{
    uint32_t info = msef != NULL ? ((uint32_t)msef[0] | ((uint32_t)msef[1] << 8)) : 0u;
    unsigned n = em->nhist < CO_EMCY_HIST_MAX ? em->nhist : CO_EMCY_HIST_MAX - 1u;
    memmove(&em->hist[1], &em->hist[0], n * sizeof(em->hist[0]));
    em->hist[0] = code | (info << 16);
    if (em->nhist < CO_EMCY_HIST_MAX) {
        em->nhist++;
    }
}
#endif

bool co_emcy_send(co_node_t *node, uint16_t code, uint8_t er, const uint8_t msef[5])
{
#if CO_EMCY_HIST_MAX > 0
    if (code != CO_EMCY_NO_ERROR) {
        record(&node->emcy, code, msef);
    }
#endif
    uint8_t st = node->nmt.state;
    if (st != CO_NMT_PREOP && st != CO_NMT_OPERATIONAL) {
        return false;
    }
    uint32_t cob = 0x80u + node->node_id;
    const co_od_entry_t *e = co_node_entry(node, 0x1014, 0);
    if (e != NULL) {
        (void)co_od_get(node, e, &cob);
    }
    if ((cob & 0x80000000u) != 0u) {
        return false; /* EMCY disabled */
    }
    co_frame_t f = {.id = (uint16_t)(cob & 0x7FFu), .dlc = 8};
    co_put_u16(&f.data[0], code);
    f.data[2] = er;
    if (msef != NULL) {
        memcpy(&f.data[3], msef, 5);
    }
    return co_node_send(node, &f);
}

uint8_t co_emcy_register(const co_node_t *node)
{
    const co_emcy_t *em = &node->emcy;
    uint8_t r = 0;
    for (unsigned i = 0; i < em->nactive; i++) {
        r = (uint8_t)(r | em->bits[i] | CO_ER_GENERIC);
    }
    return r;
}

static int find(const co_emcy_t *em, uint16_t code)
{
    for (unsigned i = 0; i < em->nactive; i++) {
        if (em->code[i] == code) {
            return (int)i;
        }
    }
    return -1;
}

bool co_emcy_active(const co_node_t *node, uint16_t code)
{
    return find(&node->emcy, code) >= 0;
}

bool co_emcy_error(co_node_t *node, uint16_t code, uint8_t er_bits, bool active,
                   const uint8_t msef[5])
{
    co_emcy_t *em = &node->emcy;
    int i = find(em, code);
    if (active) {
        if (i >= 0 || em->nactive >= CO_EMCY_ACTIVE_MAX) {
            return false;
        }
        em->code[em->nactive] = code;
        em->bits[em->nactive] = er_bits;
        em->nactive++;
        (void)co_emcy_send(node, code, co_emcy_register(node), msef);
        return true;
    }
    if (i < 0) {
        return false;
    }
    em->nactive--;
    em->code[i] = em->code[em->nactive];
    em->bits[i] = em->bits[em->nactive];
    if (em->nactive == 0u) {
        (void)co_emcy_send(node, CO_EMCY_NO_ERROR, 0, NULL);
    }
    return true;
}

co_res_t co_emcy_read_register(co_node_t *node, const co_od_entry_t *e, uint32_t *value)
{
    (void)e;
    *value = co_emcy_register(node);
    return CO_OK;
}

#if CO_EMCY_HIST_MAX > 0
co_res_t co_emcy_read_hist(co_node_t *node, const co_od_entry_t *e, uint32_t *value)
{
    const co_emcy_t *em = &node->emcy;
    if (e->sub == 0u) {
        /* No more than the dictionary has entries for (the JD keeps one). */
        uint32_t depth = 0;
        while (depth < CO_EMCY_HIST_MAX &&
               co_node_entry(node, 0x1003, (uint8_t)(depth + 1u)) != NULL) {
            depth++;
        }
        *value = co_min_u32(em->nhist, depth);
        return CO_OK;
    }
    if (e->sub > em->nhist) {
        return CO_E_NO_DATA; /* no error recorded at that depth */
    }
    *value = em->hist[e->sub - 1u];
    return CO_OK;
}

co_res_t co_emcy_write_hist(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    if (e->sub != 0u) {
        return CO_E_RO;
    }
    if (value != 0u) {
        return CO_E_VAL; /* only 0 (clear the history) may be written */
    }
    node->emcy.nhist = 0;
    return CO_OK;
}
#endif

co_res_t co_emcy_write_cobid(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    /* Bits 30 and 29 zero, an 11-bit CAN-ID that is not restricted while
     * the EMCY is valid (CiA 301 7.3.5, 7.5.2.21). */
    co_res_t c = co_cobid_check(value, false, true);
    if (c != CO_OK) {
        return c;
    }
    uint32_t cur;
    (void)co_od_get(node, e, &cur);
    bool cur_valid = (cur & 0x80000000u) == 0u;
    if (cur_valid && (value & 0x80000000u) == 0u && (value & 0x7FFu) != (cur & 0x7FFu)) {
        return CO_E_VAL; /* CiA 301: change the CAN-ID only while invalid */
    }
    return co_od_store(node, e, value);
}

void co_emcy_can_state(co_node_t *node, co_can_state_t old_state)
{
    /* CiA 301 codes: error passive while it lasts; bus-off reported once
     * the node is back on the bus (nothing can be sent while off). */
    (void)co_emcy_error(node, 0x8120, CO_ER_COMM, node->can_state == CO_CAN_PASSIVE, NULL);
    if (old_state == CO_CAN_BUSOFF) {
        (void)co_emcy_error(node, 0x8140, CO_ER_COMM, true, NULL);
        (void)co_emcy_error(node, 0x8140, CO_ER_COMM, false, NULL);
    }
}
