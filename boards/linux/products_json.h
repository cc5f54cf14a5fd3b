/*
 * products_json.h - `canopen-sensor --list-products --json`: every product
 * the program runs, as JSON, for tools that discover what exists.
 */
#ifndef LINUX_PRODUCTS_JSON_H
#define LINUX_PRODUCTS_JSON_H

#include <stdio.h>

#include "product.h"

/*
 * Write a JSON array to f, one object a product (the --list-products
 * order): id, family, summary, vendor, nodes, default_node_ids (one per
 * node), default_bitrate_kbps, lss, inputs (name, unit, limit, initial:
 * numbers in the input's unit), faults (names), and from its family's
 * declaration (od/<family>/family.cmake): template (an EXAMPLE family's),
 * mcu_image (one is built per MCU board: every product but a template),
 * mcu_config (the node config that image fixes, null for none: a product
 * of two nodes). Builds each product's instance in a local buffer to read
 * its nodes' node-IDs (nothing is sent, no port is called). only: that product alone (--product),
 * NULL: all. Returns 0, or -1 when f reported a write error.
 */
int products_json(FILE *f, const product_t *only);

#endif /* LINUX_PRODUCTS_JSON_H */
