/*
 * dst.h - the Danfoss DST inclinometer family: DST X730 and DST X710.
 * Behaviour shared by the family lives in dst.c; the two models'
 * dictionaries, one list with the X710's differences marked, in
 * dst_tables.c.
 */
#ifndef DST_H
#define DST_H

#include "co_incl.h"
#include "co_node.h"
#include "product.h"

/* 0x4001 error bits (manual "Error code"). */
#define DST_ERR_SENSOR 0x01u   /* sensor error or angle beyond the limit */
#define DST_ERR_PROGRAM 0x10u  /* program checksum error */
#define DST_ERR_FLASH 0x20u    /* flash write-cycle limit reached */
#define DST_ERR_CHECKSUM 0x40u /* stored parameter checksum error */

/* Manual: "maximum 100,000 write cycles" of the parameter memory. */
#define DST_WRITE_LIMIT 100000u

typedef struct dst_variant {
    const co_node_cfg_t *cfg; /* the model's dictionary and hooks */
    uint8_t axes;             /* 2: X/Y, 1: Z */
    bool wrap;                /* Z-360: full turn */
    int32_t limit_mdeg;       /* output stop and error angle (0: none) */
} dst_variant_t;

/* Stored by "save" (class PARA). */
typedef struct dst_para {
    uint32_t emcy_cobid;   /* 0x1014 */
    uint16_t hb_ms;        /* 0x1017 */
    uint16_t event_ms;     /* 0x1800 sub 5 */
    uint16_t inhibit_ms;   /* 0x1800 sub 3, X710 only (X730: fixed 0) */
    uint8_t tx_type;       /* 0x1800 sub 2 */
    uint8_t filter;        /* 0x2001 */
    uint8_t err_behaviour; /* 0x4000 */
    uint8_t autostart;     /* 0x5000 */
    uint8_t pdo_coding;    /* 0x5001 (X730 only): 0 big endian, 1 little endian */
    co_incl_para_t incl;   /* 0x6000..0x6024 */
} dst_para_t;

/* RAM only: the two copies of node-ID and bit rate being written. */
typedef struct dst_vol {
    uint8_t id[2]; /* 0x20F0, 0x20F1 */
    uint8_t br[2]; /* 0x20F2, 0x20F3 */
} dst_vol_t;

typedef struct dst_dev {
    /* Bytes first: short loads on the Cortex-M0 (see co_node_t). */
    uint8_t errors;   /* 0x4001 */
    uint8_t reported; /* 0x4001 as last sent by EMCY */
    bool sensor_fault;
    uint8_t filter_active;
    dst_para_t para;
    dst_vol_t vol;
    co_lss_para_t lss;
    co_incl_t incl;
    co_node_t node;
} dst_dev_t;

/* Shared behaviour: node ops and dictionary hooks. */
extern const co_node_ops_t dst_ops;
extern const co_led_timing_t dst_led;
void dst_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[]);
void dst_sample(void *mem, const int32_t values[], uint32_t faults);
co_res_t dst_write_hb(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_emcy_cobid(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_tx_type(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_id(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_bitrate(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_coding(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t dst_read_errors(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t dst_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v);

/* Node configs (dictionary and hooks) of the two models. */
extern const co_node_cfg_t dst_x730_cfg;
extern const co_node_cfg_t dst_x710_cfg;

extern const product_t dst_x730_xy10, dst_x730_xy15, dst_x730_xy20, dst_x730_xy30, dst_x730_xy45,
    dst_x730_xy60, dst_x730_xy90, dst_x730_z360;
extern const product_t dst_x710_xy10, dst_x710_xy15, dst_x710_xy20, dst_x710_xy30, dst_x710_xy45,
    dst_x710_xy60, dst_x710_xy90, dst_x710_z360;

/* The error limit of each variant: 110 % of the range, +-87 deg on the
 * +-90 variant; shared by both models (section 9 of either manual). */
#define DST_LIMIT_XY10 11000
#define DST_LIMIT_XY15 16500
#define DST_LIMIT_XY20 22000
#define DST_LIMIT_XY30 33000
#define DST_LIMIT_XY45 49500
#define DST_LIMIT_XY60 66000
#define DST_LIMIT_XY90 87000

/* A product of the family: symbol, ID, description, variant, input names, config. */
#define DST_PRODUCT(sym, idstr, text, var, ins, cfgp)                                              \
    const product_t sym = {.id = PRODUCT_TEXT(idstr),                                              \
                           .summary = PRODUCT_TEXT(text),                                          \
                           .inputs = ins, /* NOLINT(bugprone-macro-parentheses): a {...} list */   \
                           .faults = {PRODUCT_FAULT("sensor"), NULL, NULL, NULL},                  \
                           .nodes = 1,                                                             \
                           .inst_size = sizeof(dst_dev_t),                                         \
                           .create = dst_create,                                                   \
                           .sample = dst_sample,                                                   \
                           .variant = &(var),                                                      \
                           .cfg = (cfgp),                                                          \
                           .vendor = PRODUCT_TEXT("Danfoss A/S")}
/* clang-format off */
#define DST_XY_INPUTS {{"x", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}, {"y", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}}
#define DST_Z_INPUTS {{"z", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}}
/* clang-format on */

#endif /* DST_H */
