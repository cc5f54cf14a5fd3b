/*
 * bitrates.c - the bit-rate code tables of the manuals, shared by the products.
 */
#include "product.h"

const uint16_t product_kbps_cia[16] = {1000, 800, 500, 250, 125, 100, 50, 20};
const uint16_t product_kbps_ifm[16] = {20, 50, 100, 125, 250, 500, 800, 1000};
const uint16_t product_kbps_pf[16] = {[1] = 125, [2] = 250, [4] = 500, [8] = 1000};

uint16_t product_kbps(const product_t *p, uint8_t code)
{
    const uint16_t *table = p->cfg != NULL ? p->cfg->kbps : NULL;
    return (table != NULL && code < 16u) ? table[code] : 0u;
}

const uint16_t product_eds_kbps[8] = {10, 20, 50, 125, 250, 500, 800, 1000};

uint8_t product_eds_bitrates(const product_t *p)
{
    uint8_t bits = 0;
    for (uint8_t code = 0; code < 16u; code++) {
        uint16_t kbps = product_kbps(p, code);
        for (unsigned i = 0; i < 8u; i++) {
            if (kbps == product_eds_kbps[i]) {
                bits |= (uint8_t)(1u << i);
            }
        }
    }
    return bits;
}
