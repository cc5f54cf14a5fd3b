/*
 * pf.h - Pepperl+Fuchs INX360D (single axis) and INY360D (dual axis)
 * inclination sensors: full-turn 0..359.9 deg outputs in 0.1 deg steps.
 * Behaviour in pf.c; the two dictionary tables in pf_inx_iny.c.
 */
#ifndef PF_H
#define PF_H

#include "co_incl.h"
#include "co_node.h"
#include "product.h"

/* Simulator faults, in product_t.faults order. */
#define PF_FAULT_RANGE_X 0x01u
#define PF_FAULT_RANGE_Y 0x02u
#define PF_FAULT_UNDERVOLTAGE 0x04u

/* EMCY codes of the manual's table (section 7.2.1 'Error messages'). */
#define PF_EMCY_RANGE_X 0x5010u
#define PF_EMCY_RANGE_Y 0x5020u

/* P+F bit-rate codes of 0x2001 (manual, section 6.3; not CiA 305's). */
#define PF_BR_125K 0x01u
#define PF_BR_250K 0x02u
#define PF_BR_500K 0x04u
#define PF_BR_1M 0x08u

/* Stored (class PARA). Decision: every SDO write is stored at once, since
 * the manual's node-ID and bit-rate changes survive a power cycle with no
 * save command (section 6.2). */
typedef struct pf_para {
    uint32_t sync_cobid; /* 0x1005 */
    uint32_t emcy_cobid; /* 0x1014 */
    uint16_t guard_ms;   /* 0x100C */
    uint8_t life_factor; /* 0x100D */
    uint16_t hb_ms;      /* 0x1017 */
    uint32_t tpdo_cobid; /* 0x1800 sub 1 */
    uint8_t tx_type;     /* 0x1800 sub 2 */
    uint16_t inhibit;    /* 0x1800 sub 3, 100 us */
    uint16_t event_ms;   /* 0x1800 sub 5 */
    uint8_t map_count;   /* 0x1A00 sub 0 */
    uint32_t map[2];     /* 0x1A00 sub 1, 2 */
    co_incl_para_t incl; /* 0x6000..0x6024 */
} pf_para_t;

typedef struct pf_dev {
    co_node_t node;
    pf_para_t para;
    co_lss_para_t lss; /* 0x2000 node-ID, 0x2001 bit rate (pending values) */
    co_incl_t incl;
    uint32_t faults; /* simulator faults (PF_FAULT_*) */
} pf_dev_t;

extern const co_node_ops_t pf_ops;
void pf_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[]);
void pf_sample(void *mem, const int32_t values[], uint32_t faults);
co_res_t pf_write_bitrate(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t pf_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t pf_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t pf_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v);

typedef struct pf_variant {
    const co_node_cfg_t *cfg;
    uint8_t axes;
} pf_variant_t;

extern const product_t pf_inx360d, pf_iny360d;
/* Node configs (dictionary and hooks) of the two models. */
extern const co_node_cfg_t pf_inx_cfg, pf_iny_cfg;

#endif /* PF_H */
