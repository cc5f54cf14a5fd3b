/*
 * product_eds.h - EDS overrides: where a product's manual asks its EDS
 * (CiA 306) to carry a value other than the one the device itself has,
 * the product lists the entry here and the EDS writer
 * (boards/linux/eds.c) follows the manual, with a comment line in the EDS
 * that gives the reason. The device keeps its own value.
 *
 * Declared next to the product's dictionary:
 *
 *     static const product_eds_override_t x_eds[] = {
 *         {.index = 0x1800, .sub = 5, .value = 0, .reason = "manual, section 12: ..."},
 *         {.index = 0}, // ends the list
 *     };
 *     const product_t x = {..., PRODUCT_EDS_OVERRIDES(x_eds)};
 *
 * An MCU image prints no EDS: there (CO_OD_NO_NAMES) product_t has no
 * such field and PRODUCT_EDS_OVERRIDES() leaves only a comma, so wrap the
 * table in #ifndef CO_OD_NO_NAMES; it costs the image nothing.
 */
#ifndef PRODUCT_EDS_H
#define PRODUCT_EDS_H

#include <stdbool.h>
#include <stdint.h>

/* One EDS entry whose DefaultValue differs from the device's default. */
typedef struct product_eds_override {
    uint16_t index; /* dictionary entry, which must exist; 0 ends a list */
    uint8_t sub;
    uint32_t value; /* the EDS's DefaultValue (numeric entries only) */
    /* The value is node-relative: DefaultValue=$NODEID+value (CiA 306),
     * for a default that is each node's own node-ID, so that one EDS
     * describes every node of a device with several. */
    bool nodeid;
    const char *reason; /* one line, no line break: the EDS comment */
} product_eds_override_t;

#ifdef CO_OD_NO_NAMES
#define PRODUCT_EDS_OVERRIDES(t)
#else
#define PRODUCT_EDS_OVERRIDES(t) .eds_overrides = (t)
#endif

#endif /* PRODUCT_EDS_H */
