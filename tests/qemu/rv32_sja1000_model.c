/*
 * rv32_sja1000_model.c - what boards/common/sja1000.c assumes of QEMU's own
 * SJA1000 model, checked on that model (ctest emu.qemu_sja1000_model): a
 * bare-metal program for the rv32-virt machine with two Kvaser PCIcan
 * cards on one QEMU can-bus. Card A sends, card B receives, and the
 * program reads B's registers as the driver does (docs/emulator.md,
 * "Remote frames with a DLC"):
 *  - RMC and RBSA read 0xFF (how the driver knows this model: rtr_skews);
 *  - a remote frame with DLC 0 leaves the FIFO in step;
 *  - one with DLC 1 is stored with its data byte, and after its release
 *    the FIFO is read from that byte (out of step);
 *  - reset mode does not bring it back in step.
 * Should a QEMU release fix its model, this fails and names the fact that
 * changed: the driver's assumption is then to be revisited. The result is
 * the exit status, through the virt machine's test device (0: all held),
 * with one line on the serial line per check.
 */
#include <stdbool.h>
#include <stdint.h>

#define UART ((volatile uint8_t *)0x10000000u)
#define TEST_DEVICE (*(volatile uint32_t *)0x00100000u) /* sifive_test: ends QEMU */
#define ECAM 0x30000000u
#define PCI_IO_WINDOW 0x03000000u
#define KVASER_ID 0x840610E8u /* vendor 10E8h (AMCC), device 8406h */
#define FRAME 16              /* PeliCAN: frame information, then ID and data */

__attribute__((naked, section(".text.start"))) void _start(void)
{
    __asm__ volatile("la sp, _estack\n"
                     "call run\n"
                     "1: j 1b\n");
}

static void put(char c)
{
    while ((UART[5] & 0x20u) == 0u) { /* QEMU's UART: always ready */
    }
    UART[0] = (uint8_t)c;
}

static void say(const char *s)
{
    for (; *s != '\0'; s++) {
        put(*s);
    }
}

static uint32_t sja[2]; /* the two controllers' I/O addresses */

static void wr(unsigned k, unsigned reg, uint8_t v)
{
    *(volatile uint8_t *)(uintptr_t)(sja[k] + reg) = v;
}

static uint8_t rd(unsigned k, unsigned reg)
{
    return *(volatile uint8_t *)(uintptr_t)(sja[k] + reg);
}

static volatile uint32_t *cfg(uint32_t dev, uint32_t off)
{
    return (volatile uint32_t *)(uintptr_t)(ECAM + (dev << 15) + off);
}

static void send(uint16_t id, bool rtr, uint8_t dlc, const uint8_t *d)
{
    wr(0, FRAME, (uint8_t)((rtr ? 0x40u : 0u) | dlc));
    wr(0, FRAME + 1u, (uint8_t)(id >> 3));
    wr(0, FRAME + 2u, (uint8_t)((id & 7u) << 5));
    for (unsigned i = 0; i < dlc; i++) {
        wr(0, FRAME + 3u + i, d[i]);
    }
    wr(0, 1, 0x01); /* CMR: transmission request */
}

static void release(void)
{
    wr(1, 1, 0x04); /* CMR: release receive buffer */
}

static unsigned failed;

static void check(bool ok, const char *what)
{
    say(ok ? "ok      " : "CHANGED ");
    say(what);
    put('\n');
    failed += ok ? 0u : 1u;
}

/* B's next message is the SDO request sent last: FI 08h, then its ID. */
static bool request_next(void)
{
    return rd(1, FRAME) == 0x08u && rd(1, FRAME + 1u) == (0x67Fu >> 3) && (rd(1, 2) & 0x01u) != 0u;
}

/* Called from _start only (LTO keeps it: used). */
__attribute__((used, noreturn)) void run(void);

void run(void)
{
    unsigned n = 0;
    for (uint32_t dev = 0; dev < 32u && n < 2u; dev++) {
        if (*cfg(dev, 0) == KVASER_ID) {
            *cfg(dev, 0x14) = 0x1000u + 0x100u * n; /* BAR 1: the SJA1000 */
            *cfg(dev, 0x04) |= 1u;                  /* I/O decoding on */
            sja[n] = PCI_IO_WINDOW + 0x1000u + 0x100u * n;
            n++;
        }
    }
    if (n < 2u) {
        say("two Kvaser PCIcan cards expected (-device kvaser_pci twice)\n");
        TEST_DEVICE = (2u << 16) | 0x3333u;
    }
    for (unsigned k = 0; k < 2u; k++) {
        wr(k, 0, 0x01);  /* reset mode */
        wr(k, 31, 0x88); /* PeliCAN, CLKOUT off */
        for (unsigned i = 0; i < 4u; i++) {
            wr(k, FRAME + i, 0x00);      /* acceptance code */
            wr(k, FRAME + 4u + i, 0xFF); /* mask: everything passes */
        }
    }
    check(rd(1, 29) == 0xFFu && rd(1, 30) == 0xFFu, "RMC and RBSA read 0xFF");
    wr(0, 0, 0x00);
    wr(1, 0, 0x00);
    const uint8_t sdo[8] = {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0};
    const uint8_t data[8] = {0xAB, 0, 0, 0, 0, 0, 0, 0};
    send(0x77F, true, 0, data);
    send(0x67F, false, 8, sdo);
    release();
    check(request_next(), "a remote frame with DLC 0 leaves the FIFO in step");
    release();
    send(0x77F, true, 1, data);
    send(0x67F, false, 8, sdo);
    check(rd(1, FRAME) == 0x41u && rd(1, FRAME + 3u) == 0xABu && rd(1, FRAME + 4u) == 0x08u,
          "a remote frame with DLC 1 is stored with its data byte");
    release();
    check(rd(1, FRAME) == 0xABu && !request_next(),
          "after its release the FIFO is read from that byte (out of step)");
    release();
    wr(1, 0, 0x01);
    wr(1, 0, 0x00);
    send(0x67F, false, 8, sdo);
    check(!request_next(), "reset mode does not bring it back in step");
    TEST_DEVICE = failed == 0u ? 0x5555u : ((1u << 16) | 0x3333u);
    for (;;) {
    }
}
