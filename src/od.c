/*
 * od.c - object dictionary access: lookup, typed read/write, limits,
 * defaults. See co_od.h.
 */
#include "co_od.h"

#include <string.h>

#include "co_node.h"

static bool is_signed(const co_od_entry_t *e)
{
    return e->type == CO_T_I8 || e->type == CO_T_I16 || e->type == CO_T_I32;
}

static bool is_number(const co_od_entry_t *e)
{
    return e->type != CO_T_VSTR;
}

static uint8_t *ram_of(const co_node_t *node, const co_od_entry_t *e)
{
    if (e->cls == CO_CLS_NONE || node->ram[e->cls] == NULL) {
        return NULL;
    }
    return (uint8_t *)node->ram[e->cls] + e->off;
}

uint32_t co_cobid_resolve(uint32_t raw, uint32_t def, uint8_t node_id)
{
    if ((raw & CO_COBID_ABS) != 0u) {
        return raw & ~CO_COBID_ABS; /* the base CAN-ID itself, as written */
    }
    if ((raw & 0x7FFu) == (def & 0x7FFu)) {
        return raw + node_id;
    }
    return raw;
}

bool co_cobid_restricted(uint32_t id)
{
    return id <= 0x07Fu || (id >= 0x101u && id <= 0x180u) || (id >= 0x581u && id <= 0x5FFu) ||
           (id >= 0x601u && id <= 0x67Fu) || (id >= 0x6E0u && id <= 0x6FFu) || id >= 0x701u;
}

co_res_t co_cobid_check(uint32_t value, bool bit30_ok, bool bit31_invalid)
{
    uint32_t reserved = bit30_ok ? 0x3FFFF800u : 0x7FFFF800u;
    bool invalid = bit31_invalid && (value & 0x80000000u) != 0u;
    if ((value & reserved) != 0u || (!invalid && co_cobid_restricted(value & 0x7FFu))) {
        return CO_E_VAL;
    }
    return CO_OK;
}

/* co_od_find's answer: the result code where asked for, and the entry. */
static const co_od_entry_t *answer(co_res_t *res, co_res_t r, const co_od_entry_t *e)
{
    if (res != NULL) {
        *res = r;
    }
    return e;
}

const co_od_entry_t *co_od_find(const co_od_t *od, uint16_t index, uint8_t sub, co_res_t *res)
{
    /* Binary search on the index alone (one 16-bit compare a step), then
     * the sub-index among that object's entries, which are sorted and
     * nearly always numbered 0, 1, 2...: try its expected place first. */
    const co_od_entry_t *t = od->entries;
    uint32_t lo = 0;
    uint32_t hi = od->count;
    uint32_t at = 0;
    while (lo < hi) {
        at = (lo + hi) / 2u;
        if (t[at].index == index) {
            break;
        }
        if (t[at].index < index) {
            lo = at + 1u;
        } else {
            hi = at;
        }
    }
    if (lo >= hi) {
        return answer(res, CO_E_NO_OBJ, NULL);
    }
    uint32_t guess = at + sub - t[at].sub; /* wraps to a huge value when below 0 */
    if (guess < od->count && t[guess].index == index && t[guess].sub == sub) {
        return answer(res, CO_OK, &t[guess]);
    }
    /* Holes in the sub-indices: walk the object's entries. */
    while (at > 0u && t[at - 1u].index == index) {
        at--;
    }
    for (; at < od->count && t[at].index == index; at++) {
        if (t[at].sub == sub) {
            return answer(res, CO_OK, &t[at]);
        }
    }
    return answer(res, CO_E_NO_SUB, NULL);
}

/* Load a size-byte little-endian host value, sign-extending INTEGERn. */
static uint32_t load_value(const co_od_entry_t *e, const uint8_t *p)
{
    switch (e->size) {
    case 1: {
        uint8_t x;
        memcpy(&x, p, 1);
        return is_signed(e) ? (uint32_t)(int32_t)(int8_t)x : x;
    }
    case 2: {
        uint16_t x;
        memcpy(&x, p, 2);
        return is_signed(e) ? (uint32_t)(int32_t)(int16_t)x : x;
    }
    default: {
        uint32_t x;
        memcpy(&x, p, 4);
        return x;
    }
    }
}

static void store_value(const co_od_entry_t *e, uint8_t *p, uint32_t v)
{
    switch (e->size) {
    case 1: {
        uint8_t x = (uint8_t)v;
        memcpy(p, &x, 1);
        break;
    }
    case 2: {
        uint16_t x = (uint16_t)v;
        memcpy(p, &x, 2);
        break;
    }
    default:
        memcpy(p, &v, 4);
        break;
    }
}

void co_od_native(const co_od_entry_t *e, uint32_t value, uint8_t *out)
{
    store_value(e, out, value);
}

co_res_t co_od_get(co_node_t *node, const co_od_entry_t *e, uint32_t *value)
{
    co_od_read_fn read = co_od_read_hook(e);
    if (read != NULL) {
        return read(node, e, value);
    }
    const uint8_t *p = ram_of(node, e);
    uint32_t v = (p != NULL) ? load_value(e, p) : e->def;
    /* A flag, not a read hook: 30 bytes less in a DST X730 image. */
    if ((e->attr & CO_A_SERIAL) != 0u) {
        v = co_node_serial(node);
    }
    if ((e->attr & CO_A_NODEID) != 0u) {
        v = co_cobid_resolve(v, e->def, node->node_id);
    }
    *value = v;
    return CO_OK;
}

co_res_t co_od_read(co_node_t *node, const co_od_entry_t *e, uint32_t at, uint8_t *buf,
                    uint32_t cap, uint32_t *len)
{
    *len = 0;
    if ((e->attr & CO_A_R) == 0u) {
        return CO_E_WO;
    }
    uint8_t tmp[4];
    const uint8_t *src;
    if (is_number(e)) {
        uint32_t v;
        co_res_t r = co_od_get(node, e, &v);
        if (r != CO_OK) {
            return r;
        }
        co_put_u32(tmp, v);
        src = tmp;
    } else {
        src = e->cdata;
    }
    uint32_t size = e->size;
    if (at >= size) {
        return CO_OK;
    }
    uint32_t n = co_min_u32(size - at, cap);
    memcpy(buf, src + at, n);
    *len = n;
    return CO_OK;
}

co_res_t co_od_store(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    uint8_t *p = ram_of(node, e);
    if (p == NULL) {
        return CO_E_RO;
    }
    if (node->od_checking) {
        return CO_OK; /* co_od_validate: the value is the one held already */
    }
    if ((e->attr & CO_A_NODEID) != 0u) {
        uint32_t base = e->def & 0x7FFu;
        if ((value & 0x7FFu) == base + node->node_id) {
            value -= node->node_id; /* the default COB-ID: keep following the node-ID */
        } else if ((value & 0x7FFu) == base) {
            value |= CO_COBID_ABS; /* the base itself: that CAN-ID, as written */
        }
    }
    store_value(e, p, value);
    return CO_OK;
}

/* Limits, then the hook or the plain store: an SDO download's value, or a
 * restored one in check mode (the hooks act on nothing). Not inlined: one
 * body for both. A product's autosave is the node's (co_node_write): the
 * dictionary never calls the store. */
static CO_NOINLINE co_res_t write_value(co_node_t *node, const co_od_entry_t *e, uint32_t v)
{
    const co_od_ext_t *x = e->ext;
    co_od_write_fn write = NULL;
    if (x != NULL) {
        if (x->min != x->max) {
            if (is_signed(e)) {
                int32_t s = (int32_t)v;
                if (s < x->min) {
                    return CO_E_VAL_LOW;
                }
                if (s > x->max) {
                    return CO_E_VAL_HIGH;
                }
            } else {
                if (v < (uint32_t)x->min) {
                    return CO_E_VAL_LOW;
                }
                if (v > (uint32_t)x->max) {
                    return CO_E_VAL_HIGH;
                }
            }
        }
        write = x->write;
    }
    return write != NULL ? write(node, e, v) : co_od_store(node, e, v);
}

co_res_t co_od_write(co_node_t *node, const co_od_entry_t *e, const uint8_t *buf, uint32_t len)
{
    if ((e->attr & CO_A_W) == 0u) {
        return CO_E_RO;
    }
    if (len > e->size) {
        return CO_E_LEN_HIGH;
    }
    if (len < e->size) {
        return CO_E_LEN_LOW;
    }
    if (!is_number(e)) {
        return CO_E_RO; /* no writable strings in any product yet */
    }
    return write_value(node, e, load_value(e, buf)); /* len is the entry's size */
}

bool co_od_validate(co_node_t *node, const co_od_entry_t *e)
{
    uint8_t *p = ram_of(node, e);
    if (p == NULL || !is_number(e)) {
        return true; /* nothing stored there to judge */
    }
    uint32_t v = load_value(e, p);
    if ((e->attr & CO_A_NODEID) != 0u) {
        v = co_cobid_resolve(v, e->def, node->node_id);
    }
    node->od_checking = true;
    co_res_t r = write_value(node, e, v);
    node->od_checking = false;
    if (r != CO_OK) {
        store_value(e, p, e->def);
    }
    return r == CO_OK;
}

void co_od_defaults(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi)
{
    const co_od_t *od = co_cfg(node)->od;
    for (uint16_t i = 0; i < od->count; i++) {
        const co_od_entry_t *e = &od->entries[i];
        uint8_t *p = ram_of(node, e);
        if (e->cls == cls && e->index >= lo && e->index <= hi && p != NULL) {
            store_value(e, p, e->def);
        }
    }
}
