/** @file
 * product.h - what a product is, for the boards: an ID, a description, the
 * simulated inputs, and how to build its nodes in caller-supplied memory.
 * The products' dictionaries and behaviour live beside this file, one
 * table per product family, written to be read next to the manual.
 */
#ifndef PRODUCT_H
#define PRODUCT_H

#include <stddef.h>

#include "co_filter.h"
#include "co_node.h"

/** Largest number of nodes one product runs (the redundant GSH-A has two). */
#define PRODUCT_MAX_NODES 2u
/** Largest number of simulated inputs ("x", "y", ...). */
#define PRODUCT_MAX_INPUTS 4u

/** A product (struct product). */
typedef struct product product_t;

/** Texts for people (ID, summary, vendor, units, fault names): an MCU image
 * prints none of them and leaves them out (CO_OD_NO_NAMES, as the
 * dictionary's names). Input names stay: they end the input list. */
#ifdef CO_OD_NO_NAMES
#define PRODUCT_TEXT(s) NULL
#else
#define PRODUCT_TEXT(s) (s)
#endif

/** Names of simulated faults: kept wherever a board takes the simulated-input
 * language by name (the Linux program, the emulated boards' serial line:
 * boards/common/serial_link.h); an image for real hardware has no simulated
 * faults and leaves them out (CO_NO_SIM_INPUT, boards/CMakeLists.txt). */
#ifdef CO_NO_SIM_INPUT
#define PRODUCT_FAULT(s) NULL
#else
#define PRODUCT_FAULT(s) (s)
#endif

/** Largest magnitude of a simulated angle input (deg): ten turns each way.
 * The angle filter takes it without saturating (board input limit vs the
 * filter's bound: co_filter.h). */
#define PRODUCT_ANGLE_LIMIT 3600
_Static_assert(PRODUCT_ANGLE_LIMIT * 1000 <= CO_FILTER_IN_MAX,
               "angle inputs must stay within the filter's input bound");

/** One simulated physical input. */
typedef struct product_input {
    const char *name; /**< "x", "length"; NULL ends the list */
    const char *unit; /**< "deg", "mm", "%" */
    int32_t initial;  /**< value at power-on, thousandths of the unit */
    int32_t limit;    /**< largest magnitude accepted, in the unit */
} product_input_t;

/** What a product is: an ID, texts, the simulated inputs, its nodes and how to build them. */
struct product {
    const char *id;                             /**< its ID ("dst-x730-xy30") */
    const char *summary;                        /**< one line for `--list-products` */
    product_input_t inputs[PRODUCT_MAX_INPUTS]; /**< simulated inputs */
    const char *faults[PRODUCT_MAX_INPUTS];     /**< simulator fault names, NULL-ended */
    unsigned nodes;                             /**< nodes this product runs */
    size_t inst_size;                           /**< bytes create() needs */
    /**
     * Build the instance in mem (inst_size bytes, aligned for any type);
     * node i talks through ports[i]. Stores the node pointers in nodes[].
     * Nothing is sent until the board calls co_node_start().
     */
    void (*create)(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[]);
    /**
     * One sensor sample: values in thousandths of the input's unit
     * (millidegrees), in the order of inputs[]; bit i of faults forces
     * fault faults[i]. Call every CO_FILTER_PERIOD_US.
     */
    void (*sample)(void *mem, const int32_t values[], uint32_t faults);
    const void *variant; /**< product-specific constants */
    /* For the EDS (CiA 306), from the same tables the firmware runs: the
     * bit rates and LSS support are the config's (product_kbps(),
     * product_eds_bitrates(), product_lss()), written there only. */
    const co_node_cfg_t *cfg; /**< node 0's configuration and dictionary */
    const char *vendor;       /**< vendor name */
#ifndef CO_OD_NO_NAMES
    /** EDS values the manual wants other than the device's (product_eds.h),
     * ended by index 0; NULL: none. Not in MCU images (they print no EDS). */
    const struct product_eds_override *eds_overrides;
#endif
};

/** Bit rates an EDS can declare (CiA 306 [DeviceInfo] BaudRate_x). @{ */
#define PRODUCT_BR_10K 0x01u
#define PRODUCT_BR_20K 0x02u
#define PRODUCT_BR_50K 0x04u
#define PRODUCT_BR_125K 0x08u
#define PRODUCT_BR_250K 0x10u
#define PRODUCT_BR_500K 0x20u
#define PRODUCT_BR_800K 0x40u
#define PRODUCT_BR_1000K 0x80u
/** @} */

/** The bit-rate code tables of the manuals (kbit/s by code). */
extern const uint16_t product_kbps_cia[16]; /**< 0 = 1000 ... 7 = 20: DST, GSH-A */
extern const uint16_t product_kbps_ifm[16]; /**< 0 = 20 ... 7 = 1000: ifm JD (3001h) */
extern const uint16_t product_kbps_pf[16];  /**< 1 = 125, 2 = 250, 4 = 500, 8 = 1000: P+F */

/** kbit/s of code for product p (its config's table, co_node_cfg_t.kbps),
 * 0 if the code means nothing or p has no config or table. */
uint16_t product_kbps(const product_t *p, uint8_t code);

/** The rates of the PRODUCT_BR_* bits, bit 0 first: CiA 306's BaudRate_x
 * keys, kbit/s. */
extern const uint16_t product_eds_kbps[8];

/** The PRODUCT_BR_* bits of the rates p's codes give (product_kbps()): the
 * bit rates its EDS declares. A rate CiA 306 has no key for (100 kbit/s)
 * is left out; 0 without a config or table. */
uint8_t product_eds_bitrates(const product_t *p);

/** Whether p's node 0 is an LSS slave (CiA 305): its config lists the
 * LSS service. */
static inline bool product_lss(const product_t *p)
{
    return p->cfg != NULL && co_cfg_has_service(p->cfg, &co_lss_service);
}

/** Every product, in `--list-products` order; NULL-terminated. */
extern const product_t *const product_list[];

/** The product with this ID, or NULL. */
const product_t *product_find(const char *id);

#endif /* PRODUCT_H */
