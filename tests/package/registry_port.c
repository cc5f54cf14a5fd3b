/* tests/package: a program on canopen::registry and canopen::linux_port
 * that calls no lp_* function itself: the stack's calls of the port
 * (co_port.h) must find the port's archive, whatever the link order. It
 * builds a registry product and never starts it: nothing is sent, and the
 * port functions are never called (their port pointers are NULL). */
#include <stdalign.h>
#include <stddef.h>
#include <stdio.h>

#include "co_node.h"
#include "product.h"

int main(void)
{
    static alignas(max_align_t) unsigned char mem[1u << 16];
    const product_t *p = product_find("jd2xxx");
    if (p == NULL || p->inst_size > sizeof(mem)) {
        return 1;
    }
    void *const ports[PRODUCT_MAX_NODES] = {NULL};
    co_node_t *nodes[PRODUCT_MAX_NODES] = {NULL};
    p->create(p, mem, ports, nodes);
    printf("%s: node-ID 0x%02X\n", p->id, (unsigned)co_node_id(nodes[0]));
    return 0;
}
