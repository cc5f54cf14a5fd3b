/*
 * test_nucleo_boot_drivers.c - the Nucleo-F042K6 board code as its
 * bootloader builds it (BOARD_BOOT: boards/common/boot_main.c), against
 * the chip's register models (tests/models): the CAN controller is read
 * from the loop, not from an interrupt (its FIFO's frames in order,
 * extended ones passed over, an overrun flag cleared), its interrupt is
 * never enabled (the bootloader's vector forwards it to the application
 * alone), and the loop never sleeps, so that a block's segments, three
 * at most in the FIFO, are taken as they come.
 */
#include <string.h>

#include "board.h"
#include "harness.h"
#include "stm32f042.h"

#define CLEAN() CHECK_EQ(stm_violations_report(), 0)

static stm_can_frame_t frame(uint32_t id, uint8_t dlc, uint8_t seed)
{
    stm_can_frame_t f = {.id = id, .dlc = dlc};
    for (unsigned i = 0; i < 8u; i++) {
        f.data[i] = (uint8_t)(seed + 13u * i);
    }
    return f;
}

static bool same(const co_frame_t *a, const stm_can_frame_t *b)
{
    unsigned n = b->dlc > 8u ? 8u : b->dlc;
    return a->id == b->id && a->rtr == b->rtr && a->dlc == n &&
           (b->rtr || memcmp(a->data, b->data, n) == 0);
}

static void boot(void)
{
    stm_chip_new();
    CHECK(board_init());
    CHECK(board_can_bitrate(500));
    stm_can_bus_idle(1);
    CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
}

static void test_fifo_read_from_the_loop(void)
{
    boot();
    co_frame_t f;
    CHECK(!board_can_receive(&f));
    /* Three frames, the FIFO's depth, no interrupt raised: read in order. */
    stm_can_frame_t in[4];
    for (unsigned i = 0; i < 3u; i++) {
        in[i] = frame(0x600u + i, (uint8_t)(6u + i), (uint8_t)i);
        in[i].rtr = i == 1u;
        CHECK_EQ(stm_can_bus_send(&in[i]), STM_CAN_FIFO0);
    }
    CHECK(!stm_can_irq());
    for (unsigned i = 0; i < 3u; i++) {
        CHECK(board_can_receive(&f) && same(&f, &in[i]));
    }
    CHECK_EQ(stm_can_fmp0(), 0);
    CHECK(!board_can_receive(&f));
    /* A fourth before the loop came: the FIFO overran (its third
     * overwritten); the flag is cleared once the FIFO is read empty. */
    for (unsigned i = 0; i < 4u; i++) {
        in[i] = frame(0x700u + i, 8, (uint8_t)(40u + i));
        CHECK_EQ(stm_can_bus_send(&in[i]), STM_CAN_FIFO0);
    }
    CHECK_EQ(stm_peek32(CAN_RF0R) & CAN_RF0R_FOVR0, CAN_RF0R_FOVR0);
    CHECK(board_can_receive(&f) && same(&f, &in[0]));
    CHECK(board_can_receive(&f) && same(&f, &in[1]));
    CHECK(board_can_receive(&f) && same(&f, &in[3]));
    CHECK(!board_can_receive(&f));
    CHECK_EQ(stm_peek32(CAN_RF0R) & CAN_RF0R_FOVR0, 0);
    /* An extended frame (a filter someone opened to them) is passed over. */
    stm_wr32(CAN_FMR, stm_peek32(CAN_FMR) | 1u);
    stm_wr32(CAN_FA1R, 0);
    stm_wr32(CAN_F0R2, 0);
    stm_wr32(CAN_FA1R, 1);
    stm_wr32(CAN_FMR, stm_peek32(CAN_FMR) & ~1u);
    stm_can_frame_t ext = frame(0x1ABCDEF, 8, 1);
    stm_can_frame_t std = frame(0x0AB, 8, 2);
    ext.ide = true;
    CHECK_EQ(stm_can_bus_send(&ext), STM_CAN_FIFO0);
    CHECK_EQ(stm_can_bus_send(&std), STM_CAN_FIFO0);
    CHECK(board_can_receive(&f) && same(&f, &std));
    CHECK(!board_can_receive(&f));
    CHECK(!stm_can_irq());
    CLEAN();
}

static void test_the_loop_never_sleeps(void)
{
    boot();
    unsigned w = stm_wfi_count();
    board_sleep(5000);
    board_sleep(0);
    CHECK_EQ(stm_wfi_count(), w);
    CLEAN();
}

int main(void)
{
    RUN(test_fifo_read_from_the_loop);
    RUN(test_the_loop_never_sleeps);
    return h_finish();
}
