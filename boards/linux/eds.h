/*
 * eds.h - the EDS (CiA 306 electronic data sheet) of a product, written
 * from the very dictionary table the firmware runs: no second copy.
 */
#ifndef LINUX_EDS_H
#define LINUX_EDS_H

#include <stdio.h>

#include "product.h"

/*
 * Write the EDS of product p's node 0 to f. Where the product lists EDS
 * overrides (product_eds.h), their values replace the device's defaults,
 * each with a comment line. Returns the number of overrides that apply to
 * no entry (none there, or a string, computed or $NODEID entry): 0 unless
 * the product's table is wrong; the EDS is written all the same.
 * Does not block beyond f's writes; keeps no pointer.
 */
int eds_write(FILE *f, const product_t *p);

#endif /* LINUX_EDS_H */
