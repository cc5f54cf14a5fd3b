/*
 * test_image.c - the program image's header and CRC (co_image.h): the
 * CRC-32 against zlib's known values, in pieces and whole; every field at
 * its offset, little-endian; each malformed header refused.
 *
 * On the host it also reads image files that tools/mkimage made
 * (tests/tools/test_mkimage.py hands them over: test_image --file ...), so
 * that the Python writer and this reader cannot drift apart, and checks
 * that the identity mkimage took from the product's EDS is what the
 * product's dictionary answers over SDO.
 */
#include "co_image.h"
#include "harness.h"

#ifndef HARNESS_BARE
#include <stdlib.h>
#endif

/* "123456789", the check string of every CRC catalogue. */
static const uint8_t check_str[9] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};

static void test_crc_known_values(void)
{
    CHECK_EQ(co_crc32(0, check_str, 9), 0xCBF43926u);
    CHECK_EQ(co_crc32(0, NULL, 0), 0);
    uint8_t all[256];
    for (unsigned i = 0; i < 256u; i++) {
        all[i] = (uint8_t)i;
    }
    CHECK_EQ(co_crc32(0, all, 256), 0x29058C73u); /* zlib.crc32(bytes(range(256))) */
    uint8_t zero = 0;
    CHECK_EQ(co_crc32(0, &zero, 1), 0xD202EF8Du); /* zlib.crc32(b"\0") */
}

/* Continued in any pieces it is the CRC of the whole: the loaders compute
 * it segment by segment as the SDO transfer delivers the image. */
static void test_crc_in_pieces(void)
{
    uint8_t all[256];
    for (unsigned i = 0; i < 256u; i++) {
        all[i] = (uint8_t)(i * 7u + 3u);
    }
    uint32_t whole = co_crc32(0, all, 256);
    for (uint32_t cut = 0; cut <= 256u; cut += 17u) {
        uint32_t c = co_crc32(0, all, cut);
        CHECK_EQ(co_crc32(c, all + cut, 256u - cut), whole);
    }
    uint32_t c = 0;
    for (uint32_t i = 0; i < 256u; i++) {
        c = co_crc32(c, all + i, 1);
    }
    CHECK_EQ(c, whole);
    CHECK_EQ(co_crc32(0x12345678u, all, 0), 0x12345678u); /* nothing added: unchanged */
}

/* h.id equals s (no strcmp: the bare-metal build has no C library). */
static bool id_is(const co_image_hdr_t *h, const char *s)
{
    unsigned i = 0;
    while (s[i] != '\0' && h->id[i] == s[i]) {
        i++;
    }
    return s[i] == '\0' && h->id[i] == '\0';
}

static void put32(uint8_t *p, uint32_t v)
{
    for (unsigned i = 0; i < 4u; i++) {
        p[i] = (uint8_t)(v >> (8u * i));
    }
}

/* A good header whose every field holds bytes of its own, so that a field
 * read at a wrong offset or in the wrong byte order shows. */
static void good(uint8_t b[CO_IMAGE_HDR_SIZE])
{
    memset(b, 0, CO_IMAGE_HDR_SIZE);
    memcpy(b, "COIM", 4);
    b[4] = 64;
    b[6] = 1;
    put32(b + 8, 0x00012345u);
    put32(b + 12, 0xC1C2C3C4u);
    put32(b + 16, 0x00000001u);
    put32(b + 20, 0x0008019Au);
    put32(b + 24, 0x21222324u);
    put32(b + 28, 0x31323334u);
    put32(b + 32, 0x41424344u);
    put32(b + 36, 0x51525354u);
    put32(b + 40, 0x08001000u);
    memcpy(b + 48, "dst-x730-xy30", 13);
}

static bool parses(const uint8_t b[CO_IMAGE_HDR_SIZE])
{
    co_image_hdr_t h;
    return co_image_parse(b, &h);
}

static void test_fields_at_their_offsets(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    good(b);
    co_image_hdr_t h;
    memset(&h, 0xAA, sizeof h);
    CHECK(co_image_parse(b, &h));
    CHECK_EQ(h.length, 0x00012345u);
    CHECK_EQ(h.crc, 0xC1C2C3C4u);
    CHECK_EQ(h.board, CO_IMAGE_BOARD_NUCLEO_F042K6);
    CHECK_EQ(h.device_type, 0x0008019Au);
    CHECK_EQ(h.vendor, 0x21222324u);
    CHECK_EQ(h.product, 0x31323334u);
    CHECK_EQ(h.revision, 0x41424344u);
    CHECK_EQ(h.program_id, 0x51525354u);
    CHECK_EQ(h.load_addr, 0x08001000u);
    CHECK(id_is(&h, "dst-x730-xy30"));
    /* The magic is the ASCII text "COIM" in file order. */
    CHECK_EQ(CO_IMAGE_MAGIC,
             ((uint32_t)'C' | (uint32_t)'O' << 8 | (uint32_t)'I' << 16 | (uint32_t)'M' << 24));
    /* The smallest image is a header alone (the Linux program's). */
    put32(b + 8, CO_IMAGE_HDR_SIZE);
    CHECK(co_image_parse(b, &h));
    CHECK_EQ(h.length, 64);
    put32(b + 8, 0xFFFFFFFFu);
    CHECK(co_image_parse(b, &h));
    CHECK_EQ(h.length, 0xFFFFFFFFu);
}

static void test_refuses_bad_magic(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    for (unsigned i = 0; i < 4u; i++) {
        good(b);
        b[i] ^= 0x20u; /* "cOIM", "CoIM", ...: each byte counts */
        CHECK(!parses(b));
    }
    good(b);
    memcpy(b, "MIOC", 4); /* the magic as a big-endian word */
    CHECK(!parses(b));
}

static void test_refuses_bad_header_size(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    const uint8_t lo[] = {0, 63, 65, 128};
    for (unsigned i = 0; i < sizeof lo; i++) {
        good(b);
        b[4] = lo[i];
        CHECK(!parses(b));
    }
    good(b);
    b[5] = 1; /* 64 + 256: the high byte counts */
    CHECK(!parses(b));
}

static void test_refuses_other_version(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    good(b);
    b[6] = 0;
    CHECK(!parses(b));
    b[6] = 2;
    CHECK(!parses(b));
    good(b);
    b[7] = 1; /* 1 + 256 */
    CHECK(!parses(b));
}

static void test_refuses_length_below_header(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    good(b);
    put32(b + 8, CO_IMAGE_HDR_SIZE - 1u);
    CHECK(!parses(b));
    put32(b + 8, 0);
    CHECK(!parses(b));
}

static void test_refuses_reserved_not_zero(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    for (unsigned i = 44; i < 48u; i++) {
        good(b);
        b[i] = 0x80u;
        CHECK(!parses(b));
    }
}

static void set_id(uint8_t b[CO_IMAGE_HDR_SIZE], const uint8_t id[CO_IMAGE_ID_LEN])
{
    good(b);
    memcpy(b + 48, id, CO_IMAGE_ID_LEN);
}

static void test_product_id(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    co_image_hdr_t h;
    /* 16 characters: no NUL in the field, one in the decoded ID. */
    set_id(b, (const uint8_t *)"abcdefghijklmnop");
    CHECK(co_image_parse(b, &h));
    CHECK(id_is(&h, "abcdefghijklmnop"));
    /* The ends of the accepted range, '!' and '~', one character alone. */
    uint8_t id[CO_IMAGE_ID_LEN] = {'!', '~'};
    set_id(b, id);
    CHECK(co_image_parse(b, &h));
    CHECK(id_is(&h, "!~"));
    memset(id, 0, sizeof id);
    id[0] = 'x';
    set_id(b, id);
    CHECK(co_image_parse(b, &h));
    CHECK(id_is(&h, "x"));
    /* Refused: empty, a space, a control character, DEL, a byte above
     * ASCII, each first and last of 16; a byte after the padding began. */
    memset(id, 0, sizeof id);
    set_id(b, id);
    CHECK(!parses(b));
    const uint8_t bad[] = {0x20, 0x1F, 0x01, 0x7F, 0x80, 0xFF};
    for (unsigned i = 0; i < sizeof bad; i++) {
        memcpy(id, "abcdefghijklmnop", CO_IMAGE_ID_LEN);
        id[0] = bad[i];
        set_id(b, id);
        CHECK(!parses(b));
        memcpy(id, "abcdefghijklmnop", CO_IMAGE_ID_LEN);
        id[CO_IMAGE_ID_LEN - 1u] = bad[i];
        set_id(b, id);
        CHECK(!parses(b));
    }
    memset(id, 0, sizeof id);
    memcpy(id, "dst", 3);
    id[CO_IMAGE_ID_LEN - 1u] = 'x'; /* "dst\0...\0x" */
    set_id(b, id);
    CHECK(!parses(b));
    id[CO_IMAGE_ID_LEN - 1u] = 0;
    id[4] = 'x'; /* "dst\0x\0..." */
    set_id(b, id);
    CHECK(!parses(b));
}

/* NULL where the header says a buffer: a contract failure, refused. */
static void test_contract(void)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    good(b);
    co_image_hdr_t h;
    unsigned before = h_asserts;
    h_expect_assert(2);
    CHECK(!co_image_parse(NULL, &h));
    CHECK(!co_image_parse(b, NULL));
    CHECK_EQ(h_asserts, before + 2u);
}

#ifndef HARNESS_BARE
/* Reads a whole file into a static buffer; returns its size (0: failed). */
static size_t read_file(const char *path, uint8_t *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "%s: cannot open\n", path);
        return 0;
    }
    size_t n = fread(buf, 1, cap, f);
    bool more = fgetc(f) != EOF;
    fclose(f);
    if (more) {
        fprintf(stderr, "%s: larger than %zu bytes\n", path, cap);
        return 0;
    }
    return n;
}

static h_dev_t dev;
static char **file_args; /* FILE BOARD PROGRAM_ID LOAD_ADDR */

/*
 * test_image --file FILE BOARD PROGRAM_ID LOAD_ADDR: FILE, made by
 * tools/mkimage, parses here with these fields, its length is the file's,
 * its CRC that of the file from CO_IMAGE_CRC_FROM on, and its identity is
 * what its product's dictionary answers (1000h, 1018h:1-3, read over SDO
 * from the product booted in the harness).
 */
static void test_file(void)
{
    static uint8_t buf[256u * 1024u];
    char **arg = file_args;
    size_t n = read_file(arg[0], buf, sizeof buf);
    co_image_hdr_t h;
    if (n < CO_IMAGE_HDR_SIZE || !co_image_parse(buf, &h)) {
        FAIL("no image header");
        return;
    }
    CHECK_EQ(h.length, n);
    CHECK_EQ(h.crc, co_crc32(0, buf + CO_IMAGE_CRC_FROM, (uint32_t)(n - CO_IMAGE_CRC_FROM)));
    CHECK_EQ(h.board, strtoul(arg[1], NULL, 0));
    CHECK_EQ(h.program_id, strtoul(arg[2], NULL, 0));
    CHECK_EQ(h.load_addr, strtoul(arg[3], NULL, 0));
    const product_t *p = product_find(h.id);
    if (p == NULL) {
        FAIL("the image's product is not in the registry");
        return;
    }
    h_boot(&dev, p, false);
    CHECK_EQ(h_read(&dev, 0x1000, 0), h.device_type);
    CHECK_EQ(h_read(&dev, 0x1018, 1), h.vendor);
    CHECK_EQ(h_read(&dev, 0x1018, 2), h.product);
    CHECK_EQ(h_read(&dev, 0x1018, 3), h.revision);
    printf("%s: %s, %lu bytes, CRC %08lX\n", arg[0], h.id, (unsigned long)h.length,
           (unsigned long)h.crc);
}
#endif

static int run_all(void)
{
    RUN(test_crc_known_values);
    RUN(test_crc_in_pieces);
    RUN(test_fields_at_their_offsets);
    RUN(test_refuses_bad_magic);
    RUN(test_refuses_bad_header_size);
    RUN(test_refuses_other_version);
    RUN(test_refuses_length_below_header);
    RUN(test_refuses_reserved_not_zero);
    RUN(test_product_id);
    RUN(test_contract);
    return h_finish();
}

#ifdef HARNESS_BARE
int main(void)
{
    return run_all();
}
#else
int main(int argc, char **argv)
{
    if (argc == 6 && strcmp(argv[1], "--file") == 0) {
        file_args = argv + 2;
        RUN(test_file);
        return h_finish();
    }
    if (argc != 1) {
        fprintf(stderr, "usage: test_image [--file IMAGE BOARD PROGRAM_ID LOAD_ADDR]\n");
        return 2;
    }
    return run_all();
}
#endif
