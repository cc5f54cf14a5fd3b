/*
 * lss.c - LSS slave. See co_lss.h.
 */
#include "co_lss.h"

#include <string.h>

#include "co_node.h"
#include "co_port.h"

enum {
    CS_SWITCH_GLOBAL = 0x04,
    CS_CONFIG_NODE_ID = 0x11,
    CS_CONFIG_BIT_TIMING = 0x13,
    CS_ACTIVATE_BIT_TIMING = 0x15,
    CS_STORE = 0x17,
    CS_SWITCH_SEL_VENDOR = 0x40,
    CS_SWITCH_SEL_SERIAL = 0x43,
    CS_SWITCH_SEL_RESULT = 0x44,
    CS_IDENT_VENDOR = 0x46,
    CS_IDENT_SERIAL_HIGH = 0x4B,
    CS_IDENT_NON_CONFIGURED = 0x4C,
    CS_IDENT_RESULT = 0x4F,
    CS_IDENT_NON_CONFIGURED_RESULT = 0x50,
    CS_FASTSCAN = 0x51,
    CS_INQUIRE_VENDOR = 0x5A,
    CS_INQUIRE_SERIAL = 0x5D,
    CS_INQUIRE_NODE_ID = 0x5E,
};

#define LSS_WAITING 0u
#define LSS_CONFIG 1u

/* kbit/s of each CiA 305 bit-timing index (5: reserved; 9: auto, none). */
static const uint16_t lss_kbps[16] = {1000, 800, 500, 250, 125, 0, 50, 20, 10};

void co_lss_reset(co_node_t *node)
{
    co_lss_t *l = &node->lss;
    uint8_t keep = l->pending_id;
    memset(l, 0, sizeof(*l));
    l->pending_id = keep;
    l->pending_br = 0xFF;
}

/* LSS address part i (0 vendor .. 3 serial) from 0x1018. */
static uint32_t address(co_node_t *node, unsigned i)
{
    uint32_t v = 0;
    const co_od_entry_t *e = co_node_entry(node, 0x1018, (uint8_t)(i + 1u));
    if (e != NULL) {
        (void)co_od_get(node, e, &v);
    }
    return v;
}

static void reply(co_node_t *node, uint8_t cs, uint8_t b1, uint32_t u32_at_1, bool use_u32)
{
    co_frame_t f = {.id = 0x7E4, .dlc = 8};
    f.data[0] = cs;
    if (use_u32) {
        co_put_u32(&f.data[1], u32_at_1);
    } else {
        f.data[1] = b1;
    }
    (void)co_node_send(node, &f);
}

static bool unconfigured(const co_node_t *node)
{
    return node->node_id == CO_LSS_UNCONFIGURED;
}

static void fastscan(co_node_t *node, const uint8_t *d)
{
    co_lss_t *l = &node->lss;
    uint32_t id_number = co_get_u32(&d[1]);
    uint8_t bit_checked = d[5];
    uint8_t sub = d[6];
    uint8_t next = d[7];
    /* Only slaves without a node-ID, in waiting state, take part (CiA 305). */
    if (!unconfigured(node) || l->state != LSS_WAITING) {
        return;
    }
    if (bit_checked == 0x80u) { /* restart: everyone answers */
        l->fs_active = true;
        l->fs_sub = 0;
        reply(node, CS_IDENT_RESULT, 0, 0, false);
        return;
    }
    if (!l->fs_active || bit_checked > 31u || sub > 3u || sub != l->fs_sub) {
        return;
    }
    uint32_t mask = ~((1u << bit_checked) - 1u); /* bits 31..bit_checked */
    if (((address(node, sub) ^ id_number) & mask) != 0u) {
        return; /* the master's guess differs from our address: no answer */
    }
    if (bit_checked == 0u) {
        l->fs_sub = next; /* this part confirmed; next goes on */
        if (sub == 3u && next == 0u) {
            l->state = LSS_CONFIG; /* the whole address matched: selected */
            l->fs_active = false;
        }
    }
    reply(node, CS_IDENT_RESULT, 0, 0, false);
}

static void identify_remote(co_node_t *node, const uint8_t *d)
{
    co_lss_t *l = &node->lss;
    uint8_t step = (uint8_t)(d[0] - CS_IDENT_VENDOR); /* 0..5 */
    uint32_t v = co_get_u32(&d[1]);
    bool ok;
    switch (step) {
    case 0: /* vendor */
    case 1: /* product */
        ok = address(node, step) == v;
        break;
    case 2: /* revision low */
    case 4: /* serial low */
        ok = address(node, step / 2u + 1u) >= v;
        break;
    default: /* revision / serial high */
        ok = address(node, step / 2u + 1u) <= v;
        break;
    }
    if (step == 0u) {
        l->identify = 0;
    }
    if (!ok || l->identify != step) {
        l->identify = 0xFF; /* mismatch: no answer for this request sequence */
        return;
    }
    l->identify++;
    if (step == 5u) {
        reply(node, CS_IDENT_RESULT, 0, 0, false);
    }
}

static void store(co_node_t *node)
{
    co_lss_t *l = &node->lss;
    uint8_t err = 0;
    uint8_t id = l->pending_id != 0u ? l->pending_id : node->node_id;
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->lss_store != NULL) {
        err = co_cfg(node)->ops->lss_store(node, id, l->pending_br);
    } else {
        co_lss_para_t *p = node->ram[CO_CLS_LSS];
        if (p == NULL) {
            err = 1; /* not supported */
        } else {
            uint8_t old_id = p->node_id;
            p->node_id = id;
            if (co_store_save(node, CO_CLS_LSS) != CO_OK) {
                p->node_id = old_id;
                err = 2;
            }
        }
    }
    reply(node, CS_STORE, err, 0, false);
}

bool co_lss_receive(co_node_t *node, const co_frame_t *f)
{
    if (f->id != 0x7E5u || f->rtr) {
        return false;
    }
    if (f->dlc != 8u) {
        return true;
    }
    /* An LSS master's answers wait for no erase either (co_store_poll). */
    node->store.sdo_at = node->now;
    co_lss_t *l = &node->lss;
    const uint8_t *d = f->data;
    uint8_t cs = d[0];
    if (cs == CS_SWITCH_GLOBAL) {
        if (d[1] > LSS_CONFIG) {
            return true; /* CiA 305 defines modes 0 and 1 only: the others change nothing */
        }
        uint8_t was = l->state;
        l->state = d[1];
        l->selective = 0;
        if (was == LSS_CONFIG && l->state == LSS_WAITING && unconfigured(node) &&
            l->pending_id != 0u && l->pending_id != CO_LSS_UNCONFIGURED) {
            co_node_reset(node, CO_RESET_COMM); /* CiA 305: now with the new node-ID */
        }
        return true;
    }
    if (cs >= CS_SWITCH_SEL_VENDOR && cs <= CS_SWITCH_SEL_SERIAL) {
        unsigned part = (unsigned)(cs - CS_SWITCH_SEL_VENDOR);
        if (part == 0u) {
            l->selective = 0;
        }
        if (l->selective == part && address(node, part) == co_get_u32(&d[1])) {
            l->selective++;
            if (l->selective == 4u) {
                l->state = LSS_CONFIG;
                l->selective = 0;
                reply(node, CS_SWITCH_SEL_RESULT, 0, 0, false);
            }
        } else {
            l->selective = 0;
        }
        return true;
    }
    if (cs >= CS_IDENT_VENDOR && cs <= CS_IDENT_SERIAL_HIGH) {
        identify_remote(node, d);
        return true;
    }
    if (cs == CS_IDENT_NON_CONFIGURED) {
        if (unconfigured(node) && (l->pending_id == 0u || l->pending_id == CO_LSS_UNCONFIGURED)) {
            reply(node, CS_IDENT_NON_CONFIGURED_RESULT, 0, 0, false);
        }
        return true;
    }
    if (cs == CS_FASTSCAN) {
        fastscan(node, d);
        return true;
    }
    if (l->state != LSS_CONFIG) {
        return true; /* the remaining services need the configuration state */
    }
    switch (cs) {
    case CS_CONFIG_NODE_ID: {
        uint8_t id = d[1];
        bool ok = (id >= 1u && id <= CO_NODE_ID_MAX) || id == CO_LSS_UNCONFIGURED;
        if (ok) {
            l->pending_id = id;
        }
        reply(node, cs, (uint8_t)(ok ? 0u : 1u), 0, false);
        break;
    }
    case CS_CONFIG_BIT_TIMING: {
        bool ok = d[1] == 0u && d[2] < 16u && ((co_cfg(node)->lss_bitrates >> d[2]) & 1u) != 0u;
        if (ok) {
            l->pending_br = d[2];
        }
        reply(node, cs, (uint8_t)(ok ? 0u : 1u), 0, false);
        break;
    }
    case CS_ACTIVATE_BIT_TIMING:
        /* The switch delay (ms) in bytes 1-2; no bit timing configured:
         * nothing to activate (no answer either way: CiA 305). */
        if (l->pending_br != 0xFFu) {
            l->switching = true;
            l->switch_at = node->now + 1000u * co_get_u16(&d[1]);
        }
        break;
    case CS_STORE:
        store(node);
        break;
    case CS_INQUIRE_NODE_ID:
        reply(node, cs, node->node_id, 0, false);
        break;
    default:
        if (cs >= CS_INQUIRE_VENDOR && cs <= CS_INQUIRE_SERIAL) {
            reply(node, cs, 0, address(node, (unsigned)(cs - CS_INQUIRE_VENDOR)), true);
        }
        break; /* unknown services: no answer (CiA 305) */
    }
    return true;
}

/* Activate bit timing: switch when the delay is over. */
static uint32_t co_lss_poll(co_node_t *node, uint32_t now)
{
    co_lss_t *l = &node->lss;
    if (!l->switching) {
        return CO_NEVER;
    }
    if (co_time_before(now, l->switch_at)) {
        return co_time_until(now, l->switch_at);
    }
    l->switching = false;
    node->can_kbps = lss_kbps[l->pending_br & 15u];
    (void)co_port_can_bitrate(node->port, node->can_kbps);
    return CO_NEVER;
}

const co_service_t co_lss_service = {
    .receive = co_lss_receive, .poll = co_lss_poll, .reset = co_lss_reset, .always = true};
