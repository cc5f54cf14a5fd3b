/*
 * registry.c - the product registry (the Linux program and the tests; an
 * MCU image links one product only, so it leaves this file out). Its rows
 * come from the families' declarations (od/<family>/family.cmake, through
 * the generated product_registry.h): a product is added there, not here.
 */
#include <string.h>

#include "product.h"
#include "product_registry.h"

/* The unit tests' build (CO_REGISTRY_EXAMPLES) also lists the templates. */
#ifdef CO_REGISTRY_EXAMPLES
#define REGISTRY_ROWS PRODUCT_REGISTRY_ROWS PRODUCT_REGISTRY_EXAMPLES
#else
#define REGISTRY_ROWS PRODUCT_REGISTRY_ROWS
#endif

const product_t *const product_list[] = {REGISTRY_ROWS NULL};

const product_t *product_find(const char *id)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        if (strcmp(product_list[i]->id, id) == 0) {
            return product_list[i];
        }
    }
    return NULL;
}
