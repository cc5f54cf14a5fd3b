/*
 * skeleton.h - the template product family (od/skeleton/family.cmake): a
 * one-axis CiA 410 inclinometer, the least a product of this stack is.
 * A family has three parts, all here:
 *   - its stored parameters and instance (below): the instance holds the
 *     node, whatever the stack's modules need from the product (here the
 *     CiA 410 state) and the product's own state;
 *   - its behaviour (skeleton.c, top): the node's product hooks
 *     (co_node_ops_t) and the dictionary's read/write hooks;
 *   - its dictionary table and configs (skeleton.c, bottom), one line per
 *     object, readable next to the manual.
 */
#ifndef SKELETON_H
#define SKELETON_H

#include "co_incl.h"
#include "co_node.h"
#include "product.h"

/* Simulator faults, in product_t.faults order. */
#define SKEL_FAULT_SENSOR 0x01u

/* Stored parameters (class PARA: 0x1010 saves them, 0x1011 restores the
 * table's defaults). Field order is the stored layout. */
typedef struct skel_para {
    uint16_t hb_ms;      /* 0x1017 */
    uint8_t tx_type;     /* 0x1800 sub 2 */
    uint16_t event_ms;   /* 0x1800 sub 5 */
    uint32_t tpdo_cobid; /* 0x1800 sub 1 */
    co_incl_para_t incl; /* 0x6000, 0x6011..0x6014 */
} skel_para_t;

typedef struct skel_dev {
    co_node_t node; /* first: the stack's node */
    skel_para_t para;
    co_incl_t incl;
    uint32_t faults; /* simulator faults (SKEL_FAULT_*) */
    int32_t sent;    /* the slope TPDO1 last carried as an event; INT32_MIN: none */
} skel_dev_t;

/* The product (registry row) and its node config (its MCU image fixes it). */
extern const product_t skel_incl;
extern const co_node_cfg_t skel_cfg;

#endif /* SKELETON_H */
