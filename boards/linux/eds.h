/*
 * eds.h - the EDS (CiA 306 electronic data sheet) of a product, written
 * from the very dictionary table the firmware runs: no second copy.
 */
#ifndef LINUX_EDS_H
#define LINUX_EDS_H

#include <stdio.h>

#include "product.h"

/* Write the EDS of product p's node 0 to f. */
void eds_write(FILE *f, const product_t *p);

#endif /* LINUX_EDS_H */
