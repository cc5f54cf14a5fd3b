/*
 * test_linux_board.c - the Linux board's simulator commands and EEPROM file.
 */
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "co_port.h"
#include "dst.h"
#include "port.h"
#include "sim.h"

#include "harness.h"

static void test_sim_commands(void)
{
    sim_t s;
    sim_init(&s, &dst_x730_xy30);
    char err[200];
    CHECK(sim_command(&s, "set x=12.345 y=-0.5", err, sizeof(err)));
    CHECK_EQ(s.values[0], 12345);
    CHECK_EQ(s.values[1], -500);
    CHECK(sim_command(&s, "set y=3", err, sizeof(err)));
    CHECK_EQ(s.values[0], 12345);
    CHECK_EQ(s.values[1], 3000);
    /* Rejected lines change nothing, not even the part that was fine. */
    CHECK(!sim_command(&s, "set x=1 y=banana", err, sizeof(err)));
    CHECK(strstr(err, "banana") != NULL);
    CHECK(!sim_command(&s, "set z=1", err, sizeof(err)));
    CHECK(strstr(err, "x=<deg> y=<deg>") != NULL);
    CHECK(!sim_command(&s, "set x=1e9", err, sizeof(err)));
    CHECK(!sim_command(&s, "set x=nan", err, sizeof(err)));
    CHECK(!sim_command(&s, "set x=", err, sizeof(err)));
    CHECK(!sim_command(&s, "set", err, sizeof(err)));
    CHECK(!sim_command(&s, "tilt 4", err, sizeof(err)));
    CHECK(!sim_command(&s, "fault sensor maybe", err, sizeof(err)));
    CHECK(!sim_command(&s, "fault motor on", err, sizeof(err)));
    CHECK_EQ(s.values[0], 12345);
    CHECK_EQ(s.values[1], 3000);
    CHECK(s.faults == 0u && !s.quit);
    CHECK(sim_command(&s, "fault sensor on", err, sizeof(err)) && s.faults == 1u);
    CHECK(sim_command(&s, "fault sensor off", err, sizeof(err)) && s.faults == 0u);
    CHECK(sim_command(&s, "", err, sizeof(err)));
    CHECK(sim_command(&s, "# comment", err, sizeof(err)));
    CHECK(sim_command(&s, "quit", err, sizeof(err)) && s.quit);
    sim_t z;
    sim_init(&z, &dst_x730_z360);
    CHECK(sim_command(&z, "set z=-179.99", err, sizeof(err)));
    CHECK_EQ(z.values[0], -179990);
    CHECK(!sim_command(&z, "set x=1", err, sizeof(err)));
}

static void test_eeprom_file(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];
    snprintf(path, sizeof(path), "%s/eeprom.bin", dir);
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    lp_port_t p = {.nvm = &n};
    FILE *devnull = fopen("/dev/null", "w");
    lp_log_open(devnull);
    CHECK_EQ(lp_nvm_open(&n, path, mem, sizeof(mem)), 0);
    struct stat st;
    CHECK(stat(path, &st) == 0 && st.st_size == (off_t)sizeof(mem)); /* created blank */
    CHECK_EQ(co_port_nvm_size(&p), sizeof(mem));
    CHECK(co_port_nvm_write(&p, 10, "abc", 3));
    CHECK(!co_port_nvm_write(&p, sizeof(mem) - 1u, "abc", 3)); /* out of range */
    char tmp[300];
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    CHECK(access(tmp, F_OK) != 0); /* no temporary left behind */
    uint8_t again[CO_STORE_NVM_SIZE];
    lp_nvm_t n2;
    CHECK_EQ(lp_nvm_open(&n2, path, again, sizeof(again)), 0);
    CHECK(memcmp(&again[10], "abc", 3) == 0);
    CHECK_EQ(again[9], 0xFF);
    /* A short file reads as erased beyond its end. */
    CHECK(truncate(path, 11) == 0);
    CHECK_EQ(lp_nvm_open(&n2, path, again, sizeof(again)), 0);
    CHECK_EQ(again[10], 'a');
    CHECK_EQ(again[11], 0xFF);
    uint8_t b;
    lp_port_t p2 = {.nvm = &n2};
    CHECK(!co_port_nvm_read(&p2, sizeof(again), &b, 1));
    unlink(path);
    rmdir(dir);
    fclose(devnull);
    lp_log_open(NULL);
}

int main(void)
{
    RUN(test_sim_commands);
    RUN(test_eeprom_file);
    return h_finish();
}
