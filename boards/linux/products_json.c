/*
 * products_json.c - see products_json.h.
 *
 * A product's family, the config of its MCU image and whether it is a
 * template come from the families' declarations (od/<family>/family.cmake):
 * cmake/families.cmake generates PRODUCT_REGISTRY_INFO, one row per
 * declared product, so that no product table repeats them.
 */
#include "products_json.h"

#include <stddef.h>
#include <string.h>

#include "co_node.h"
#include "product.h"
#include "product_registry.h"

static const product_registry_info_t info[] = {PRODUCT_REGISTRY_INFO{.id = NULL}};

/* What the declarations say of p (by its ID); family NULL where none
 * declares it (a product a test made up). */
static product_registry_info_t info_of(const product_t *p)
{
    for (size_t i = 0; info[i].id != NULL; i++) {
        if (p->id != NULL && strcmp(info[i].id, p->id) == 0) {
            return info[i];
        }
    }
    return (product_registry_info_t){.id = p->id};
}

/* s as a JSON string ("null" for NULL); control characters escaped. */
static void put_string(FILE *f, const char *s)
{
    if (s == NULL) {
        fputs("null", f);
        return;
    }
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)s; *c != '\0'; c++) {
        if (*c == '"' || *c == '\\') {
            fprintf(f, "\\%c", *c);
        } else if (*c < 0x20u) {
            fprintf(f, "\\u%04x", *c);
        } else {
            fputc(*c, f);
        }
    }
    fputc('"', f);
}

/* A value in thousandths of a unit as a JSON number. */
static void put_milli(FILE *f, int32_t v)
{
    long long a = v < 0 ? -(long long)v : (long long)v;
    fprintf(f, "%s%lld", v < 0 ? "-" : "", a / 1000);
    if (a % 1000 != 0) {
        fprintf(f, ".%03lld", a % 1000);
    }
}

static void put_product(FILE *f, const product_t *p)
{
    /* The instance, only to read each node's node-ID after co_node_init
     * (create() calls no port: NULL ports are never used). */
    _Alignas(max_align_t) unsigned char mem[sizeof(product_any_t)];
    void *ports[PRODUCT_MAX_NODES] = {NULL};
    co_node_t *nodes[PRODUCT_MAX_NODES] = {NULL};
    unsigned n = p->nodes <= PRODUCT_MAX_NODES ? p->nodes : PRODUCT_MAX_NODES;
    fputs("  {\"id\": ", f);
    put_string(f, p->id);
    product_registry_info_t decl = info_of(p);
    fputs(", \"family\": ", f);
    put_string(f, decl.family != NULL ? decl.family : "");
    fputs(", \"summary\": ", f);
    put_string(f, p->summary);
    fputs(", \"vendor\": ", f);
    put_string(f, p->vendor);
    fprintf(f, ", \"nodes\": %u, \"default_node_ids\": [", n);
    if (p->inst_size <= sizeof(mem)) {
        p->create(p, mem, ports, nodes);
    }
    for (unsigned i = 0; i < n; i++) {
        fprintf(f, "%s%u", i > 0u ? ", " : "",
                nodes[i] != NULL ? co_node_id(nodes[i]) : p->cfg->default_node_id);
    }
    fprintf(f, "], \"default_bitrate_kbps\": %u, \"lss\": %s,\n   \"inputs\": [",
            (unsigned)product_kbps(p, p->cfg->default_bitrate), product_lss(p) ? "true" : "false");
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        const product_input_t *in = &p->inputs[i];
        fputs(i > 0u ? ", {\"name\": " : "{\"name\": ", f);
        put_string(f, in->name);
        fputs(", \"unit\": ", f);
        put_string(f, in->unit);
        fprintf(f, ", \"limit\": %ld, \"initial\": ", (long)in->limit);
        put_milli(f, in->initial);
        fputc('}', f);
    }
    fputs("],\n   \"faults\": [", f);
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->faults[i] != NULL; i++) {
        fputs(i > 0u ? ", " : "", f);
        put_string(f, p->faults[i]);
    }
    fputs("],\n   \"template\": ", f);
    fputs(decl.example ? "true" : "false", f);
    /* Every declared product but a template has an image per MCU board
     * (boards/CMakeLists.txt). */
    fprintf(f, ", \"mcu_image\": %s, \"mcu_config\": ",
            decl.family != NULL && !decl.example ? "true" : "false");
    put_string(f, decl.mcu_cfg);
    fputs("}", f);
}

int products_json(FILE *f, const product_t *only)
{
    fputs("[\n", f);
    bool first = true;
    for (size_t i = 0; product_list[i] != NULL; i++) {
        if (only != NULL && product_list[i] != only) {
            continue;
        }
        fputs(first ? "" : ",\n", f);
        put_product(f, product_list[i]);
        first = false;
    }
    fputs(first ? "" : "\n", f);
    fputs("]\n", f);
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}
