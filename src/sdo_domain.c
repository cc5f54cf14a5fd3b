/*
 * sdo_domain.c - the SDO server's DOMAIN downloads (co_sdo_domain_fn,
 * co_sdo.h): the bytes of a segmented or block download collect in the
 * transfer buffer and go to the config's handler a piece at a time.
 * Linked only where a config has a handler (co_node_cfg_t.sdo_domain).
 */
#include <string.h>

#include "co_sdo.h"
#include "sdo_internal.h"

co_res_t sdo_domain_hand(co_node_t *node, bool end)
{
    co_sdo_t *sdo = &node->sdo;
    uint32_t n = sdo->pos;
    sdo->pos = 0;
    co_res_t r = co_cfg(node)->sdo_domain(node, sdo->e, sdo->done, sdo->buf, n, end);
    sdo->done += n;
    return r;
}

co_res_t sdo_domain_take(co_node_t *node, const uint8_t *src, uint32_t n)
{
    co_sdo_t *sdo = &node->sdo;
    while (n > 0u) {
        if (sdo->pos == SDO_DOMAIN_PIECE) {
            co_res_t r = sdo_domain_hand(node, false);
            if (r != CO_OK) {
                return r;
            }
        }
        uint32_t k = co_min_u32(n, SDO_DOMAIN_PIECE - sdo->pos);
        memcpy(&sdo->buf[sdo->pos], src, k);
        sdo->pos += k;
        src += k;
        n -= k;
    }
    return CO_OK;
}
