/*
 * my_sensor.h - a product outside the stack's tree: a one-axis CiA 410
 * inclinometer ("my-incl"), built against the installed canopen_sensors
 * package only (CMakeLists.txt; docs/library.md of the stack).
 */
#ifndef MY_SENSOR_H
#define MY_SENSOR_H

#include "co_incl.h"
#include "co_node.h"
#include "product.h"

/* Input faults, in product_t.faults order. */
#define MY_FAULT_ELEMENT 0x01u

/* Stored parameters (0x1010 saves them, 0x1011 restores the table's
 * defaults). Field order is the stored layout. */
typedef struct my_para {
    uint16_t hb_ms;      /* 0x1017 */
    uint16_t event_ms;   /* 0x1800 sub 5 */
    uint32_t tpdo_cobid; /* 0x1800 sub 1 */
    uint8_t tx_type;     /* 0x1800 sub 2 */
    co_incl_para_t incl; /* 0x6000, 0x6012 */
} my_para_t;

typedef struct my_dev {
    co_node_t node; /* first: the stack's node */
    my_para_t para;
    co_incl_t incl;
    uint32_t faults; /* MY_FAULT_* */
    int32_t last;    /* the slope TPDO1 last sent as an event; INT32_MIN: none */
} my_dev_t;

/* The product and its node config. */
extern const product_t my_incl;
extern const co_node_cfg_t my_cfg;

#endif /* MY_SENSOR_H */
