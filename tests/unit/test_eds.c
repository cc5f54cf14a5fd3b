/*
 * test_eds.c - the EDS writer (boards/linux/eds.c): every product's EDS
 * is written with all its overrides applied, and an override follows its
 * manual in the EDS (with a comment line) while the device keeps its own
 * value. dcfchk and the canopen package read every EDS in
 * tests/integration/test_eds.py.
 */
#include <stdlib.h>

#include <string.h>

#include "dst.h"
#include "eds.h"
#include "gsh.h"
#include "jd.h"
#include "pf.h"
#include "product_eds.h"

#include "harness.h"

/* The EDS of p as a string (malloc'd; the caller frees it); *unused gets
 * eds_write's result. */
static char *eds_text(const product_t *p, int *unused)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (f == NULL) {
        return NULL;
    }
    *unused = eds_write(f, p);
    fclose(f);
    return buf;
}

/* The section "[name]" of an EDS, up to its blank line, copied to out. */
static void section(const char *eds, const char *name, char *out, size_t len)
{
    out[0] = '\0';
    char head[32];
    snprintf(head, sizeof(head), "[%s]\n", name);
    const char *s = strstr(eds, head);
    if (s != NULL) {
        const char *end = strstr(s, "\n\n");
        size_t n = end != NULL ? (size_t)(end - s) : strlen(s);
        snprintf(out, len, "%.*s", (int)n, s);
    }
}

static void test_every_product_applies_its_overrides(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        int unused = -1;
        char *eds = eds_text(product_list[i], &unused);
        CHECK(eds != NULL);
        CHECK_EQ(unused, 0);
        if (unused != 0) {
            fprintf(stderr, "  %s: %d EDS overrides apply to no entry\n", product_list[i]->id,
                    unused);
        }
        free(eds);
    }
}

/* GSH-A manual: "In the EDS file this default value must be set to 0,
 * otherwise errors will be generated" (section 12); the device keeps 100. */
static void test_gsh_event_timer(void)
{
    const product_t *gsh[] = {&gsh_a, &gsh_a_redundant};
    for (unsigned i = 0; i < 2u; i++) {
        int unused = -1;
        char *eds = eds_text(gsh[i], &unused);
        char s[1024];
        section(eds != NULL ? eds : "", "1800sub5", s, sizeof(s));
        CHECK(strstr(s, "\nDefaultValue=0x0\n") != NULL);
        CHECK(strstr(s, "\n; the device's default is 0x64; ") != NULL);
        CHECK(strstr(s, "otherwise errors will be generated") != NULL);
        CHECK(strstr(s, "0x64\n") == NULL);
        /* Nothing else changed: sub 3 still carries the device's value. */
        section(eds != NULL ? eds : "", "1800sub3", s, sizeof(s));
        CHECK(strstr(s, "\nDefaultValue=0x4\n") != NULL && strchr(s, ';') == NULL);
        free(eds);
    }
    /* The device itself: 100 ms. */
    const co_od_entry_t *e = co_od_find(gsh_ch1_cfg.od, 0x1800, 5, NULL);
    CHECK(e != NULL && e->def == 100u);
}

/* A value computed at run time (a live input) has no DefaultValue; the
 * GSH-A's node-ID setting 0x3001 is each node's own node-ID ($NODEID),
 * so that one EDS describes both nodes of the redundant version. */
static void test_live_values_and_node_relative_default(void)
{
    int unused = -1;
    char *eds = eds_text(&gsh_a_redundant, &unused);
    CHECK(eds != NULL && unused == 0);
    char s[1024];
    section(eds != NULL ? eds : "", "6004", s, sizeof(s));
    CHECK(strstr(s, "ParameterName=") != NULL && strstr(s, "DefaultValue") == NULL);
    section(eds != NULL ? eds : "", "6810", s, sizeof(s));
    CHECK(strstr(s, "ParameterName=") != NULL && strstr(s, "DefaultValue") == NULL);
    section(eds != NULL ? eds : "", "3001", s, sizeof(s));
    CHECK(strstr(s, "\n; the device's default is each node's own node-ID: ") != NULL);
    CHECK(strstr(s, "\nDefaultValue=$NODEID+0x0\n") != NULL);
    free(eds);
}

/* Without overrides, the EDS carries the device's own default. */
static void test_no_override_keeps_the_device_value(void)
{
    product_t p = gsh_a;
    p.eds_overrides = NULL;
    int unused = -1;
    char *eds = eds_text(&p, &unused);
    char s[1024];
    section(eds != NULL ? eds : "", "1800sub5", s, sizeof(s));
    CHECK_EQ(unused, 0);
    CHECK(strstr(s, "\nDefaultValue=0x64\n") != NULL && strchr(s, ';') == NULL);
    free(eds);
}

/* Overrides that name no entry, or an entry that cannot take one, are
 * counted and change nothing; a signed entry is written in decimal. */
static void test_wrong_overrides_are_counted(void)
{
    static const product_eds_override_t bad[] = {
        {.index = 0x1801, .sub = 5, .value = 0, .reason = "no such entry"},
        {.index = 0x1008, .sub = 0, .value = 0, .reason = "a string"},
        {.index = 0x1800, .sub = 1, .value = 0x200, .reason = "$NODEID-relative"},
        {.index = 0x6810, .sub = 0, .value = 7, .reason = "computed at run time"},
        {.index = 0x1017, .sub = 0, .value = 1000, .reason = "a fine one"},
        {.index = 0x1017, .sub = 0, .value = 2000, .reason = "the same entry twice"},
        {.index = 0},
    };
    product_t p = gsh_a;
    p.eds_overrides = bad;
    int unused = -1;
    char *eds = eds_text(&p, &unused);
    CHECK_EQ(unused, 5);
    char s[1024];
    section(eds != NULL ? eds : "", "1017", s, sizeof(s));
    CHECK(strstr(s, "\nDefaultValue=0x3E8\n") != NULL && strstr(s, "a fine one") != NULL);
    section(eds != NULL ? eds : "", "1800sub1", s, sizeof(s));
    CHECK(strstr(s, "\nDefaultValue=$NODEID+0x180\n") != NULL && strchr(s, ';') == NULL);
    free(eds);
}

/* [DeviceInfo] BaudRate_x: 1 exactly for the rates one of the product's
 * bit-rate codes gives (the manuals' tables: the CiA order on the DST and
 * GSH-A, code 0 = 1000 kbit/s; ifm's on the JD, code 0 = 20 kbit/s). */
static void test_baud_rates_are_the_codes(void)
{
    static const struct {
        const product_t *p;
        const char *want;
    } cases[] = {
        {&dst_x730_xy30, "BaudRate_10=0\nBaudRate_20=1\nBaudRate_50=1\nBaudRate_125=1\n"
                         "BaudRate_250=1\nBaudRate_500=1\nBaudRate_800=1\nBaudRate_1000=1\n"},
        {&jd2xxx, "BaudRate_10=0\nBaudRate_20=1\nBaudRate_50=1\nBaudRate_125=1\n"
                  "BaudRate_250=1\nBaudRate_500=1\nBaudRate_800=1\nBaudRate_1000=1\n"},
        {&pf_inx360d, "BaudRate_10=0\nBaudRate_20=0\nBaudRate_50=0\nBaudRate_125=1\n"
                      "BaudRate_250=1\nBaudRate_500=1\nBaudRate_800=0\nBaudRate_1000=1\n"},
    };
    for (unsigned k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        int unused = 0;
        char *text = eds_text(cases[k].p, &unused);
        CHECK(text != NULL && strstr(text, cases[k].want) != NULL);
        free(text);
    }
}

/* Every code of the table counts, the last (15) too, and every CiA 306
 * rate, the lowest (10 kbit/s) too: a product whose table has 10 kbit/s at
 * code 15 alone declares BaudRate_10 alone. */
static void test_baud_rates_every_code_and_rate(void)
{
    static const uint16_t table[16] = {[15] = 10};
    const co_node_cfg_t cfg = {.kbps = table};
    const product_t p = {.id = "edge", .cfg = &cfg};
    CHECK_EQ(product_kbps(&p, 15), 10);
    CHECK_EQ(product_kbps(&p, 16), 0);
    CHECK_EQ(product_eds_bitrates(&p), PRODUCT_BR_10K);
}

int main(void)
{
    RUN(test_every_product_applies_its_overrides);
    RUN(test_gsh_event_timer);
    RUN(test_no_override_keeps_the_device_value);
    RUN(test_live_values_and_node_relative_default);
    RUN(test_wrong_overrides_are_counted);
    RUN(test_baud_rates_are_the_codes);
    RUN(test_baud_rates_every_code_and_rate);
    return h_finish();
}
