/*
 * linux_main.c - my-incl on a SocketCAN interface, with the installed
 * Linux port (canopen::linux_port): one node, its EEPROM in a file (or in
 * RAM), the slope held at --angle. It answers SDO, sends its heartbeat
 * and TPDO1, and takes NMT, until SIGINT or SIGTERM.
 */
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "can_port.h"
#include "co_filter.h"
#include "log.h"
#include "my_sensor.h"
#include "nvm_file.h"

static const char usage[] = "usage: my-sensor [--angle DEG] [--nvm FILE] IFACE\n"
                            "  my-incl, a one-axis inclinometer, as node 0x21 on the SocketCAN\n"
                            "  interface IFACE (250 kbit/s; vcan ignores the rate).\n"
                            "  --angle DEG  the slope it measures (default 0)\n"
                            "  --nvm FILE   its EEPROM (default: RAM, lost at exit)\n";

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

/* Monotonic microseconds, wrapping as the stack expects. */
static uint32_t now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u);
}

int main(int argc, char **argv)
{
    const char *iface = NULL;
    const char *nvm_path = NULL;
    double angle = 0.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0) {
            fputs(usage, stdout);
            return 0;
        } else if (strcmp(argv[i], "--angle") == 0 && i + 1 < argc) {
            char *end;
            angle = strtod(argv[++i], &end);
            if (*end != '\0' || angle < -PRODUCT_ANGLE_LIMIT || angle > PRODUCT_ANGLE_LIMIT) {
                fprintf(stderr, "my-sensor: --angle %s: not a slope in degrees\n", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--nvm") == 0 && i + 1 < argc) {
            nvm_path = argv[++i];
        } else if (argv[i][0] != '-' && iface == NULL) {
            iface = argv[i];
        } else {
            fprintf(stderr, "my-sensor: %s: unexpected\n%s", argv[i], usage);
            return 2;
        }
    }
    if (iface == NULL) {
        fprintf(stderr, "my-sensor: no interface given\n%s", usage);
        return 2;
    }

    static uint8_t nvm_mem[CO_STORE_NVM_SIZE];
    static lp_nvm_t nvm;
    static lp_port_t port;
    static lp_tx_t tx;
    static my_dev_t dev;
    char err[600];
    lp_log_start();
    if (lp_nvm_open(&nvm, "--nvm", nvm_path, nvm_mem, sizeof(nvm_mem), err, sizeof(err)) != 0 ||
        lp_nvm_lock(&nvm, "--nvm", nvm_path, err, sizeof(err)) != 0) {
        fprintf(stderr, "my-sensor: %s\n", err);
        return 1;
    }
    uint32_t t = now_us();
    if (lp_open(&port, iface, 0, &nvm, t, err, sizeof(err)) != 0) {
        fprintf(stderr, "my-sensor: %s: %s\n", iface, err);
        return 1;
    }
    if (lp_tx_open(&tx, err, sizeof(err)) != 0) {
        fprintf(stderr, "my-sensor: %s\n", err);
        lp_close(&port);
        return 1;
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);

    void *const ports[1] = {&port};
    co_node_t *nodes[1];
    my_incl.create(&my_incl, &dev, ports, nodes);
    co_node_t *node = nodes[0];
    co_node_set_serial(node, 1u);
    int32_t values[PRODUCT_MAX_INPUTS] = {(int32_t)(angle * 1000.0)};
    my_incl.sample(&dev, values, 0);
    co_node_start(node, t);
    lp_log("my-incl: node-ID 0x%02X on %s", co_node_id(node), iface);
    uint32_t next_sample = t + CO_FILTER_PERIOD_US;
    while (!stop) {
        t = now_us();
        if (!co_time_before(t, next_sample)) {
            my_incl.sample(&dev, values, 0);
            next_sample += CO_FILTER_PERIOD_US;
        }
        co_frame_t f;
        while (lp_read(&port, &f, t) == 1) {
            co_node_receive(node, &f, t);
            (void)co_node_poll(node, t);
        }
        uint32_t wait = co_time_until(t, next_sample);
        wait = co_min_u32(wait, lp_poll(&port, t));
        co_node_set_can_state(node, lp_can_state(&port));
        wait = co_min_u32(wait, co_node_poll(node, t));
        lp_filter(&port, node); /* the CAN-IDs it consumes now */
        (void)lp_tx_flush(&tx, &port, 1);
        struct pollfd pfd = {.fd = port.fd, .events = POLLIN};
        (void)poll(&pfd, 1, (int)((co_min_u32(wait, 1000000u) + 999u) / 1000u));
    }
    lp_tx_close(&tx);
    lp_close(&port);
    lp_nvm_unlock(&nvm);
    return 0;
}
