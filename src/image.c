/*
 * image.c - the program image's header and its CRC. See co_image.h; the
 * format's description for people is docs/program-download.md.
 *
 * Both functions go into every bootloader (4 KB on the Cortex-M0), so they
 * are written for size: the CRC bit by bit with no table, the header read
 * byte by byte with one little-endian helper.
 */
#include "co_image.h"

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* The product ID field: one or more printable characters without spaces
 * (an ID names a product, "dst-x730-xy30"), then NULs to the end. A byte
 * after the first NUL that is not NUL is refused: two images of one
 * product must have byte-equal headers but for the fields that differ. */
static bool id_ok(const uint8_t *f, char *out)
{
    uint32_t n = 0;
    while (n < CO_IMAGE_ID_LEN && f[n] != 0u) {
        if (f[n] < 0x21u || f[n] > 0x7Eu) {
            return false;
        }
        out[n] = (char)f[n];
        n++;
    }
    if (n == 0u) {
        return false;
    }
    out[n] = '\0';
    for (uint32_t i = n; i < CO_IMAGE_ID_LEN; i++) {
        if (f[i] != 0u) {
            return false;
        }
    }
    return true;
}

bool co_image_parse(const uint8_t b[CO_IMAGE_HDR_SIZE], co_image_hdr_t *h)
{
    if (!CO_CHECK(b != NULL && h != NULL)) {
        return false;
    }
    /* The header's words 0-11, then the product ID (co_image.h's table):
     * read in a loop, which costs a 4 KiB bootloader less than a line a
     * field. */
    uint32_t w[12];
    for (unsigned i = 0; i < 12u; i++) {
        w[i] = le32(b + (size_t)4u * i);
    }
    if (w[0] != CO_IMAGE_MAGIC ||
        w[1] != (CO_IMAGE_HDR_SIZE | ((uint32_t)CO_IMAGE_VERSION << 16)) ||
        w[2] < CO_IMAGE_HDR_SIZE || w[11] != 0u) {
        return false;
    }
    h->length = w[2];
    h->crc = w[3];
    h->board = w[4];
    h->device_type = w[5];
    h->vendor = w[6];
    h->product = w[7];
    h->revision = w[8];
    h->program_id = w[9];
    h->load_addr = w[10];
    return id_ok(b + 48, h->id);
}

/* Not inlined: the store's two callers (a record's read and its write)
 * share one copy; with link-time optimisation each would get its own. No
 * CO_CHECK of data: it would cost every image bytes on each call path
 * (NULL with len 0 reads nothing). */
CO_NOINLINE uint32_t co_crc32(uint32_t crc, const void *data, uint32_t len)
{
    const uint8_t *p = data;
    crc = ~crc;
    for (uint32_t i = 0; i < len; i++) {
        crc ^= p[i];
        for (unsigned bit = 0; bit < 8u; bit++) {
            /* 0 - (crc & 1): all ones when the bit shifted out is set. */
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}
