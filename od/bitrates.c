/*
 * bitrates.c - the bit-rate code tables of the manuals, shared by the products.
 */
#include "product.h"

const uint16_t product_kbps_cia[16] = {1000, 800, 500, 250, 125, 100, 50, 20};
const uint16_t product_kbps_ifm[16] = {20, 50, 100, 125, 250, 500, 800, 1000};
const uint16_t product_kbps_pf[16] = {[1] = 125, [2] = 250, [4] = 500, [8] = 1000};

uint16_t product_kbps(const product_t *p, uint8_t code)
{
    return (p->kbps != NULL && code < 16u) ? p->kbps[code] : 0u;
}

