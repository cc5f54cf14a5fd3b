/*
 * gsh.h - Gefran GSH-A draw-wire length + tilt sensor (CiA 406 + CiA 410,
 * multiple logical device). Each measuring channel is one CANopen node;
 * the redundant version is two independent nodes (0x13, 0x14) in one
 * device. Behaviour in gsh.c, the dictionary in gsh_a.c.
 */
#ifndef GSH_H
#define GSH_H

#include "co_incl.h"
#include "co_node.h"
#include "product.h"

/* Alarm word (PDO bytes 5-6, little-endian; manual, section 9 'Error
 * handling', the alarm table). */
#define GSH_ALARM_UNDER_EXTENSION 0x0002u
#define GSH_ALARM_OVER_EXTENSION 0x0004u
#define GSH_ALARM_FIELD_HIGH 0x0010u
#define GSH_ALARM_FIELD_LOW 0x0020u
#define GSH_ALARM_EXTENSION_ELEMENT 0x0200u
#define GSH_ALARM_TILT_ELEMENT 0x0400u

/* Simulator inputs and faults, in product_t order. */
#define GSH_IN_LENGTH 0 /* mm of extracted wire */
#define GSH_IN_ANGLE 1  /* deg */
#define GSH_IN_FIELD 2  /* magnet field, % of nominal */
#define GSH_FAULT_EXTENSION_ELEMENT 0x01u
#define GSH_FAULT_TILT_ELEMENT 0x02u

/* Decisions where the manual is silent (it gives no stroke for channel 2's
 * "backward direction" and no alarm thresholds), as build parameters: */
#define GSH_STROKE_MM 8000     /* measuring range; channel 2 = stroke - channel 1 */
#define GSH_FIELD_LOW_PCT 50   /* magnet field below this: "too low" */
#define GSH_FIELD_HIGH_PCT 150 /* above this: "too high" */

/* Stored by 0x1010 (class PARA). */
typedef struct gsh_para {
    uint32_t sync_cobid; /* 0x1005 (no effect: type 254 is fixed) */
    uint16_t hb_ms;      /* 0x1017 */
    uint16_t event_ms;   /* 0x1800 sub 5 */
    uint8_t autostart;   /* 0x5000 */
} gsh_para_t;

typedef struct gsh_chan {
    co_node_t node;
    gsh_para_t para;
    co_lss_para_t lss;        /* 0x3000 bit rate, 0x3001 node-ID */
    co_incl_para_t incl_para; /* fixed: 0.1 deg, channel 2 counts backwards */
    co_incl_t incl;
    uint16_t position_mm; /* 0x6004 */
    uint16_t alarms;
    uint8_t counter;       /* PDO byte 7 of the next PDO */
    uint8_t sent_counter;  /* 0x2111: byte 7 of the last PDO sent (0 before one) */
    uint8_t sent_checksum; /* 0x2112: its byte 8 */
} gsh_chan_t;

typedef struct gsh_dev {
    gsh_chan_t ch[PRODUCT_MAX_NODES];
    unsigned nchan;
} gsh_dev_t;

/*
 * PDO byte 8: the checksum over bytes 1..7 (d[0..6]). The manual does not
 * give the rule. Decision: (sum + 254) mod 255, the simplest rule that
 * reproduces both of the manual's example frames (section 11); the plain
 * byte sum misses one. Replace this one function once a capture of a real
 * unit decides (a frame whose byte sum is below 256 or above 510 does).
 */
uint8_t gsh_pdo_checksum(const uint8_t d[7]);

extern const co_node_ops_t gsh_ops;
void gsh_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[]);
void gsh_sample(void *mem, const int32_t values[], uint32_t faults);
co_res_t gsh_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v);
co_res_t gsh_read_position(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t gsh_read_angle(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t gsh_read_alarm(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t gsh_read_counter(co_node_t *n, const co_od_entry_t *e, uint32_t *v);
co_res_t gsh_read_checksum(co_node_t *n, const co_od_entry_t *e, uint32_t *v);

extern const co_node_cfg_t gsh_ch1_cfg, gsh_ch2_cfg;
extern const product_t gsh_a, gsh_a_redundant;

#endif /* GSH_H */
