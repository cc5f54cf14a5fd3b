/*
 * registry.c - the product registry (the Linux program and the tests;
 * an MCU image links one product only, so it leaves this file out).
 */
#include <string.h>

#include "dst.h"
#include "gsh.h"
#include "jd.h"
#include "pf.h"
#include "product.h"

const product_t *const product_list[] = {
    &dst_x730_xy10, &dst_x730_xy15, &dst_x730_xy20, &dst_x730_xy30, &dst_x730_xy45,
    &dst_x730_xy60, &dst_x730_xy90, &dst_x730_z360, &dst_x710_xy10, &dst_x710_xy15,
    &dst_x710_xy20, &dst_x710_xy30, &dst_x710_xy45, &dst_x710_xy60, &dst_x710_xy90,
    &dst_x710_z360, &gsh_a, &gsh_a_redundant, &jd1xxx, &jd2xxx, &pf_inx360d, &pf_iny360d, NULL,
};

const product_t *product_find(const char *id)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        if (strcmp(product_list[i]->id, id) == 0) {
            return product_list[i];
        }
    }
    return NULL;
}
