/*
 * fuzz_products.h - the product an input's first byte selects, for both
 * harnesses. By ID, not by place in product_list: the seeds were written
 * for FZ_PRODUCT_IDS (fuzz_format.h), and the registry's order follows the
 * families' folders, so a new family may land anywhere in it. The order
 * here is FZ_PRODUCT_IDS first (the seeds keep their products), then every
 * other product of the registry (a new one is fuzzed at once).
 */
#ifndef FUZZ_PRODUCTS_H
#define FUZZ_PRODUCTS_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_format.h"
#include "product.h"

#define FZ_PRODUCTS_MAX 64u

typedef struct fz_products {
    const product_t *order[FZ_PRODUCTS_MAX];
    unsigned count;
} fz_products_t;

/* Build the order once (LLVMFuzzerInitialize). A seed's product that the
 * registry no longer has is reported: rewrite the seeds (tools/fuzz --seeds). */
static inline void fz_products_init(fz_products_t *p)
{
    static const char *const ids[FZ_PRODUCT_COUNT] = {FZ_PRODUCT_IDS};
    p->count = 0;
    for (unsigned i = 0; i < FZ_PRODUCT_COUNT; i++) {
        const product_t *prod = product_find(ids[i]);
        if (prod == NULL) {
            fprintf(stderr,
                    "fuzz: the seeds' product %s is gone: update fuzz_format.h and "
                    "rewrite the seeds (tools/fuzz --seeds)\n",
                    ids[i]);
            abort();
        }
        p->order[p->count++] = prod;
    }
    for (unsigned n = 0; product_list[n] != NULL; n++) {
        bool seeded = false;
        for (unsigned i = 0; i < FZ_PRODUCT_COUNT; i++) {
            seeded = seeded || strcmp(product_list[n]->id, ids[i]) == 0;
        }
        if (!seeded) {
            if (p->count == FZ_PRODUCTS_MAX) {
                fprintf(stderr, "fuzz: more than %u products: raise FZ_PRODUCTS_MAX\n",
                        FZ_PRODUCTS_MAX);
                abort();
            }
            p->order[p->count++] = product_list[n];
        }
    }
}

/* The product of selector byte b. */
static inline const product_t *fz_product(const fz_products_t *p, uint8_t b)
{
    return p->order[b % p->count];
}

#endif /* FUZZ_PRODUCTS_H */
