/*
 * eds.c - see eds.h.
 */
#include "eds.h"

#include <stdbool.h>

#include "product_eds.h"

static bool is_signed(const co_od_entry_t *e)
{
    return e->type == CO_T_I8 || e->type == CO_T_I16 || e->type == CO_T_I32;
}

static const char *access_type(const co_od_entry_t *e)
{
    if ((e->attr & CO_A_CONST) != 0u) {
        return "const";
    }
    switch (e->attr & CO_A_RW) {
    case CO_A_R:
        return "ro";
    case CO_A_W:
        return "wo";
    default:
        return "rw";
    }
}

/* v as the EDS writes e's values: signed decimal or unsigned hex. */
static void format_value(char *buf, size_t len, const co_od_entry_t *e, uint32_t v)
{
    if (is_signed(e)) {
        int32_t s = (int32_t)v;
        if (e->size == 1u) {
            s = (int8_t)v;
        } else if (e->size == 2u) {
            s = (int16_t)v;
        }
        snprintf(buf, len, "%ld", (long)s);
    } else {
        snprintf(buf, len, "0x%lX", (unsigned long)v);
    }
}

static void value(FILE *f, const char *key, const co_od_entry_t *e, uint32_t v)
{
    char buf[16];
    format_value(buf, sizeof(buf), e, v);
    fprintf(f, "%s=%s\n", key, buf);
}

/* The override of p for entry e, or NULL. Only numeric entries with a
 * default of their own can have one: not strings, not values computed at
 * run time, not $NODEID-relative ones. */
static const product_eds_override_t *override_of(const product_t *p, const co_od_entry_t *e)
{
    if (p->eds_overrides == NULL || e->type == CO_T_VSTR || (e->attr & CO_A_NODEID) != 0u ||
        co_od_read_hook(e) != NULL) {
        return NULL;
    }
    for (const product_eds_override_t *o = p->eds_overrides; o->index != 0u; o++) {
        if (o->index == e->index && o->sub == e->sub) {
            return o;
        }
    }
    return NULL;
}

static void entry_body(FILE *f, const product_t *p, const co_od_entry_t *e, const char *name)
{
    fprintf(f, "ParameterName=%s\n", name);
    fprintf(f, "ObjectType=0x7\n");
    fprintf(f, "DataType=0x%04X\n", (unsigned)e->type);
    fprintf(f, "AccessType=%s\n", access_type(e));
    const product_eds_override_t *o = override_of(p, e);
    if (e->type == CO_T_VSTR) {
        fprintf(f, "DefaultValue=%.*s\n", (int)e->size, (const char *)e->cdata);
    } else if ((e->attr & CO_A_NODEID) != 0u) {
        fprintf(f, "DefaultValue=$NODEID+0x%lX\n", (unsigned long)e->def);
    } else if ((e->attr & CO_A_SERIAL) != 0u || co_od_read_hook(e) != NULL ||
               e->type == CO_T_DOMAIN) {
        /* No DefaultValue (CiA 306 lets an entry omit it) for 1018h:04,
         * the unit's serial: a device-specific value here would make a
         * master that checks it at boot (1F88h) reject every other unit;
         * nor for what is computed at run time (a live input, an error
         * state), so that a master that compares or writes defaults finds
         * none that the device does not read; nor for a DOMAIN (1F50h:1,
         * the program data), which has no value to read. (One branch: two
         * empty ones are a clone to clang-tidy.) */
    } else if (o != NULL && o->nodeid) {
        fprintf(f, "; the device's default is each node's own node-ID: %s\n", o->reason);
        fprintf(f, "DefaultValue=$NODEID+0x%lX\n", (unsigned long)o->value);
    } else if (o != NULL) {
        /* The manual asks the EDS for another value than the device's:
         * an EDS comment line says so (CiA 306: lines starting with ';'). */
        char dev[16];
        format_value(dev, sizeof(dev), e, e->def);
        fprintf(f,
                "; the device's default is %s; this EDS gives the value its manual asks for: %s\n",
                dev, o->reason);
        value(f, "DefaultValue", e, o->value);
    } else {
        value(f, "DefaultValue", e, e->def);
    }
    if (e->ext != NULL && e->ext->min != e->ext->max) {
        value(f, "LowLimit", e, (uint32_t)e->ext->min);
        value(f, "HighLimit", e, (uint32_t)e->ext->max);
    }
    fprintf(f, "PDOMapping=%d\n\n", (e->attr & CO_A_PDO) != 0u ? 1 : 0);
}

typedef enum { MANDATORY, OPTIONAL, MANUFACTURER } group_t;

static group_t group_of(uint16_t index)
{
    if (index == 0x1000u || index == 0x1001u || index == 0x1018u) {
        return MANDATORY;
    }
    return (index >= 0x2000u && index < 0x6000u) ? MANUFACTURER : OPTIONAL;
}

static void object_list(FILE *f, const co_od_t *od, group_t g, const char *section)
{
    unsigned n = 0;
    for (uint16_t i = 0; i < od->count; i++) {
        bool first = i == 0u || od->entries[i - 1u].index != od->entries[i].index;
        n += first && group_of(od->entries[i].index) == g;
    }
    fprintf(f, "[%s]\nSupportedObjects=%u\n", section, n);
    n = 0;
    for (uint16_t i = 0; i < od->count; i++) {
        bool first = i == 0u || od->entries[i - 1u].index != od->entries[i].index;
        if (first && group_of(od->entries[i].index) == g) {
            fprintf(f, "%u=0x%04X\n", ++n, od->entries[i].index);
        }
    }
    fprintf(f, "\n");
}

int eds_write(FILE *f, const product_t *p)
{
    const co_od_t *od = p->cfg->od;
    unsigned tpdos = 0;
    bool dynamic = false;
    for (uint16_t i = 0; i < od->count; i++) {
        const co_od_entry_t *e = &od->entries[i];
        tpdos += e->index >= 0x1800u && e->index < 0x1A00u && e->sub == 0u;
        dynamic |= e->index >= 0x1A00u && e->index < 0x1C00u && (e->attr & CO_A_W) != 0u;
    }
    const co_od_entry_t *ident = co_od_find(od, 0x1018, 2, NULL);
    const co_od_entry_t *vendor = co_od_find(od, 0x1018, 1, NULL);
    const co_od_entry_t *rev = co_od_find(od, 0x1018, 3, NULL);
    fprintf(f,
            "[FileInfo]\nFileName=%s.eds\nFileVersion=1\nFileRevision=0\nEDSVersion=4.0\n"
            "Description=%s\nCreatedBy=canopen-sensor --eds (generated from the firmware's "
            "dictionary)\n\n",
            p->id, p->summary);
    fprintf(f,
            "[DeviceInfo]\nVendorName=%s\nVendorNumber=0x%lX\nProductName=%s\n"
            "ProductNumber=0x%lX\nRevisionNumber=0x%lX\nOrderCode=%s\n",
            p->vendor, vendor != NULL ? (unsigned long)vendor->def : 0ul, p->summary,
            ident != NULL ? (unsigned long)ident->def : 0ul,
            rev != NULL ? (unsigned long)rev->def : 0ul, p->id);
    unsigned bitrates = product_eds_bitrates(p);
    for (unsigned i = 0; i < 8u; i++) {
        fprintf(f, "BaudRate_%u=%u\n", (unsigned)product_eds_kbps[i], (bitrates >> i) & 1u);
    }
    fprintf(f,
            "SimpleBootUpMaster=0\nSimpleBootUpSlave=1\nGranularity=%d\n"
            "DynamicChannelsSupported=0\nGroupMessaging=0\nNrOfRXPDO=0\nNrOfTXPDO=%u\n"
            "LSS_Supported=%d\nCompactPDO=0\n\n",
            dynamic ? 8 : 0, tpdos, product_lss(p) ? 1 : 0);
    fprintf(f, "[DummyUsage]\n");
    for (unsigned i = 1; i <= 7u; i++) {
        fprintf(f, "Dummy%04u=0\n", i);
    }
    fprintf(f, "\n");
    object_list(f, od, MANDATORY, "MandatoryObjects");
    object_list(f, od, OPTIONAL, "OptionalObjects");
    object_list(f, od, MANUFACTURER, "ManufacturerObjects");

    for (uint16_t i = 0; i < od->count;) {
        uint16_t index = od->entries[i].index;
        uint16_t end = i;
        while (end < od->count && od->entries[end].index == index) {
            end++;
        }
        const co_od_entry_t *e = &od->entries[i];
        const char *name = e->name != NULL ? e->name : "Object";
        if (end - i == 1 && e->sub == 0u) {
            fprintf(f, "[%04X]\n", index);
            entry_body(f, p, e, name);
        } else {
            fprintf(f, "[%04X]\nParameterName=%s\nObjectType=0x9\nSubNumber=%u\n\n", index, name,
                    (unsigned)(end - i));
            for (uint16_t k = i; k < end; k++) {
                const co_od_entry_t *s = &od->entries[k];
                char sub_name[96];
                if (s->sub == 0u) {
                    snprintf(sub_name, sizeof(sub_name), "Highest sub-index supported");
                } else {
                    snprintf(sub_name, sizeof(sub_name), "%s", s->name != NULL ? s->name : "Sub");
                }
                fprintf(f, "[%04Xsub%X]\n", index, s->sub);
                entry_body(f, p, s, sub_name);
            }
        }
        i = end;
    }
    /* Overrides that found no entry to apply to: a mistake in the product's table. */
    int unused = 0;
    for (const product_eds_override_t *o = p->eds_overrides; o != NULL && o->index != 0u; o++) {
        const co_od_entry_t *e = co_od_find(od, o->index, o->sub, NULL);
        unused += e == NULL || override_of(p, e) != o;
    }
    return unused;
}
