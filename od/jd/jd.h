/*
 * jd.h - ifm electronic JD1xxx (single axis, 0..360 deg) and JD2xxx (dual
 * axis, +-90 deg) dynamic inclination sensors. Behaviour in jd.c, the
 * dictionaries in jd_tables.c.
 */
#ifndef JD_H
#define JD_H

#include "co_incl.h"
#include "co_node.h"
#include "product.h"

#define JD_MAF_MAX 250u                /* 0x3100 moving-average length */
#define JD_SAVE_RESET_CODE 0x55AAAA55u /* 0x2300 */

/* Stored (class PARA), grouped by 0x1010 sub 2 (1000h-1FFFh), 3 (6000h-),
 * 4 (2000h-5FFFh). */
typedef struct jd_para {
    /* communication */
    uint32_t sync_cobid;  /* 0x1005 */
    uint16_t guard_ms;    /* 0x100C */
    uint8_t life_factor;  /* 0x100D */
    uint32_t emcy_cobid;  /* 0x1014 */
    uint32_t hb_consumer; /* 0x1016 sub 1 */
    uint16_t hb_ms;       /* 0x1017 */
    uint32_t cob[2];      /* 0x1800/0x1801 sub 1 */
    uint8_t type[2];      /* sub 2 */
    uint16_t inhibit[2];  /* sub 3, 100 us */
    uint16_t event_ms;    /* sub 5 of both, and 0x2200: one value (manual, 8.9.6) */
    uint8_t map_count[2]; /* 0x1A00/0x1A01 sub 0 */
    uint32_t map[2][2];   /* sub 1, 2 */
    /* manufacturer */
    uint8_t fast_boot;   /* 0x2700 */
    uint8_t node_number; /* 0x3000: node-ID - 1 */
    uint8_t bitrate;     /* 0x3001 code */
    uint8_t termination; /* 0x3002 */
    uint8_t autostart;   /* 0x3005 */
    uint16_t recursive;  /* 0x3022 (undocumented; stored, no effect) */
    uint16_t maf;        /* 0x3100 */
    /* application, per axis (X/Z = 0, Y = 1) */
    uint16_t resolution; /* 0x6000 */
    uint8_t op16[2];     /* 0x6011 / 0x6021 */
    uint8_t op32[2];     /* 0x6111 / 0x6121 */
    int32_t preset[2];   /* 0x6012 = 0x2600 = 0x6112 (hard-wired, manual 9.18) */
    int16_t off16[2];    /* 0x6013 */
    int32_t off32[2];    /* 0x6113 */
    int16_t diff16[2];   /* 0x6014 */
    int32_t diff32[2];   /* 0x6114 */
} jd_para_t;

typedef struct jd_dev {
    co_node_t node;
    jd_para_t para;
    uint8_t axes;        /* 1: JD1 (Z, 0..360), 2: JD2 (X, Y, +-90) */
    int32_t raw[2];      /* physical angle after the MAF, mdeg */
    co_incl_meas_t meas; /* raw in resolution units, one turn in them */
    int32_t prev[2];     /* previous sample, for the gyro rates */
    int16_t gyro[3];     /* 0x3400.. 0.1 deg/s */
    int16_t accel[3];    /* 0x3403.. mg */
    uint16_t temp;       /* 0x3411, 0.1 degC */
    uint16_t maf_len;    /* window the buffer was filled for */
    uint16_t maf_pos, maf_fill;
    int32_t maf_sum[2];
    int32_t maf_buf[2][JD_MAF_MAX];
} jd_dev_t;

extern const co_node_ops_t jd_ops;
void jd_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[]);
void jd_sample(void *mem, const int32_t values[], uint32_t faults);

co_res_t jd_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t jd_write_inhibit(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t jd_write_save_reset(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t jd_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t jd_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t jd_write_diff(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t jd_read_preset(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t jd_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t jd_read_sensor(co_node_t *n, const co_od_entry_t *e, uint32_t *v);

extern const product_t jd1xxx, jd2xxx;
/* Node configs (dictionary and hooks) of the two models. */
extern const co_node_cfg_t jd1_cfg, jd2_cfg;

#endif /* JD_H */
