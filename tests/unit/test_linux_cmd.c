/*
 * test_linux_cmd.c - the Linux program's line language (boards/linux/cmd.h)
 * on instances without sockets: line assembly, the verbs' answers,
 * selectors, all-or-none, `can` on the selected nodes, `get`, `quit`; and
 * its agreement with the emulated boards' serial line (serial_link.h).
 */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app.h"
#include "cmd.h"
#include "dst.h"
#include "gsh.h"
#include "jd.h"
#include "serial_link.h"

#include "harness.h"

static app_t app;
static const char *const vcan0[PRODUCT_MAX_NODES] = {"vcan0", "vcan0"};

/* A fresh app of the given products (a NULL-ended list), node-IDs from
 * 0x20 on, nothing opened. */
static void make(const product_t *const prods[])
{
    memset(&app, 0, sizeof(app));
    uint8_t id = 0x20;
    for (unsigned k = 0; prods[k] != NULL; k++) {
        CHECK(app_add(&app, prods[k], vcan0, id, 1) == (int)k);
        app_inst_t *in = &app.inst[k];
        char err[200];
        CHECK(lp_nvm_open(&in->nvm, "--nvm", NULL, in->nvm_mem, sizeof(in->nvm_mem), err,
                          sizeof(err)) == 0); /* RAM */
        id = (uint8_t)(id + prods[k]->nodes);
    }
}

/* The answer to one line at time now (static buffer). */
static const char *ask_at(const char *line, uint32_t now)
{
    static char reply[CMD_REPLY_MAX + 1u];
    cmd_line(&app, CMD_STDIN, line, now, reply, sizeof(reply));
    return reply;
}

static const char *ask(const char *line)
{
    return ask_at(line, 1000u);
}

static bool is(const char *got, const char *want)
{
    if (strcmp(got, want) != 0) {
        fprintf(stderr, "  got  '%s'\n  want '%s'\n", got, want);
        return false;
    }
    return true;
}

static bool starts(const char *got, const char *want)
{
    if (strncmp(got, want, strlen(want)) != 0) {
        fprintf(stderr, "  got  '%s'\n  want '%s...'\n", got, want);
        return false;
    }
    return true;
}

static void test_set_fault_get(void)
{
    make((const product_t *const[]){&dst_x730_xy30, NULL});
    const sim_t *s = &app.inst[0].sim;
    CHECK(is(ask("set x=12.345 y=-0.5"), "ok"));
    CHECK_EQ(s->values[0], 12345);
    CHECK_EQ(s->values[1], -500);
    CHECK(is(ask("get"), "ok x=12.345 y=-0.500 nmt=initialising"));
    /* Rejected lines change nothing, not even the part that was fine. */
    CHECK(is(ask("set x=1 y=banana"), "error: 'y=banana': not a number within +-3600"));
    CHECK(is(ask("set z=1"), "error: 'z=1': expected x=<deg> y=<deg>"));
    CHECK(is(ask("set x=1e9"), "error: 'x=1e9': not a number within +-3600"));
    CHECK(starts(ask("set x=nan"), "error: 'x=nan'"));
    CHECK(starts(ask("set x="), "error: 'x='"));
    CHECK(is(ask("set"), "error: usage: set x=<deg> y=<deg>"));
    CHECK_EQ(s->values[0], 12345);
    CHECK(is(ask("fault sensor maybe"), "error: usage: fault sensor on|off"));
    CHECK(is(ask("fault motor on"), "error: usage: fault sensor on|off"));
    CHECK_EQ(s->faults, 0u);
    CHECK(is(ask("fault sensor on"), "ok") && s->faults == 1u);
    CHECK(is(ask("fault sensor off"), "ok") && s->faults == 0u);
    CHECK(is(ask("get x"), "error: get takes nothing after it"));
    CHECK(is(ask("quit now"), "error: quit takes nothing after it") && !app.quit);
    CHECK(is(ask("quit"), "ok") && app.quit);
    make((const product_t *const[]){&dst_x730_z360, NULL});
    CHECK(is(ask("set z=-179.99"), "ok"));
    CHECK_EQ(app.inst[0].sim.values[0], -179990);
    CHECK(starts(ask("set x=1"), "error: 'x=1': expected z=<deg>"));
    /* The JD has no simulated faults: said so, not "usage: fault  on|off". */
    make((const product_t *const[]){&jd1xxx, NULL});
    CHECK(is(ask("fault sensor on"), "error: jd1xxx has no simulated faults"));
    char d[256];
    cmd_describe(&jd1xxx, d, sizeof(d));
    CHECK(strncmp(d, "set z=<deg> ", 12) == 0 && strstr(d, "; no faults") != NULL);
    cmd_describe(&dst_x730_xy30, d, sizeof(d));
    CHECK(is(d, "set x=<deg> y=<deg>; fault sensor"));
}

/* Every answer names the verbs in the table's order: the one list. */
static void test_verb_table(void)
{
    make((const product_t *const[]){&dst_x730_xy30, NULL});
    char names[200];
    cmd_verb_names(names, sizeof(names));
    CHECK(is(names, "set, ramp, sine, noise, replay, fault, can, unplug, heartbeat, get, quit"));
    CHECK(is(ask("tilt 5"), "error: unknown command 'tilt' (set, ramp, sine, noise, replay, "
                            "fault, can, unplug, heartbeat, get, quit)"));
    CHECK(is(ask("0x20"), "error: no command (set, ramp, sine, noise, replay, fault, can, unplug, "
                          "heartbeat, get, quit)"));
    CHECK(is(ask("0x20 # note"), "error: no command (set, ramp, sine, noise, replay, fault, "
                                 "can, unplug, heartbeat, get, quit)"));
    /* Each verb is served: a line of it gets its own answer, never
     * "unknown command". */
    for (unsigned v = 0; v < cmd_nverbs; v++) {
        CHECK(strstr(ask(cmd_verbs[v].name), "unknown command") == NULL);
        CHECK(cmd_verbs[v].parse != NULL && cmd_verbs[v].usage != NULL);
        CHECK((cmd_verbs[v].apply != NULL) == (cmd_verbs[v].scope != CMD_QUERY));
    }
    /* --help's rows come from the table: one a verb, in its order, each
     * line within 79 columns (continuations indented). */
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    cmd_usage(f);
    fclose(f);
    unsigned rows = 0;
    for (const char *p = text; *p != '\0'; p += strcspn(p, "\n") + 1u) {
        CHECK(strcspn(p, "\n") <= 79u);
        if (p[0] == ' ' && p[1] == ' ' && p[2] != ' ') {
            CHECK(rows < cmd_nverbs &&
                  strncmp(p + 2, cmd_verbs[rows].name, strlen(cmd_verbs[rows].name)) == 0);
            rows++;
        }
        if (p[strcspn(p, "\n")] == '\0') {
            break;
        }
    }
    CHECK_EQ(rows, cmd_nverbs);
    CHECK(strstr(text, "\n  can bus-off [SECONDS] | passive | warning | active\n") != NULL);
    free(text);
}

static void test_can_on_selected_nodes(void)
{
    make((const product_t *const[]){&jd2xxx, &gsh_a_redundant, NULL});
    CHECK_EQ(app.nnodes, 3u);
    CHECK(is(ask("can bus-off"), "ok")); /* no selector: the first instance */
    CHECK_EQ(lp_can_state(&app.ports[0]), CO_CAN_BUSOFF);
    CHECK_EQ(co_node_can_state(app.nodes[0]), CO_CAN_BUSOFF);
    CHECK_EQ(lp_can_state(&app.ports[1]), CO_CAN_ACTIVE);
    CHECK(is(ask("@2 can passive"), "ok")); /* one node of the redundant GSH-A */
    CHECK_EQ(lp_can_state(&app.ports[2]), CO_CAN_PASSIVE);
    CHECK_EQ(lp_can_state(&app.ports[1]), CO_CAN_ACTIVE);
    CHECK(is(ask("@all can warning"), "ok"));
    CHECK_EQ(lp_can_state(&app.ports[0]), CO_CAN_BUSOFF); /* bus-off ends by itself only */
    for (unsigned i = 1; i < 3u; i++) {
        CHECK_EQ(lp_can_state(&app.ports[i]), CO_CAN_WARNING);
    }
    CHECK(is(ask("can bus-off 1.5"), "ok"));
    CHECK_EQ(app.ports[0].sim_recover_at, 1000u + 1500000u + (1408u * 1000u + 124u) / 125u);
    CHECK(is(ask("can"), "error: usage: can bus-off [SECONDS] | can passive | can warning | "
                         "can active"));
    CHECK(is(ask("can off"), ask("can")));
    CHECK(is(ask("can bus-off -1"), "error: '-1': not a number of seconds within 0..1800"));
    CHECK(starts(ask("can bus-off 1800.5"), "error: '1800.5'"));
    CHECK(is(ask("can bus-off 1 2"), ask("can")));
    CHECK(is(ask("can passive 3"), ask("can")));
    CHECK(is(ask("can bus-off 1800"), "ok"));
}

/* `unplug` and `heartbeat` on the selected nodes' ports: a pulled cable
 * takes every frame and sends none, its CAN state unchanged, until its
 * time or `unplug off`; a stopped heartbeat keeps the boot-up; `get`
 * names what is on; bad lines change nothing. */
static void test_unplug_and_heartbeat(void)
{
    make((const product_t *const[]){&jd2xxx, &gsh_a_redundant, NULL});
    co_frame_t hb = {.id = 0x721, .dlc = 1, .data = {0x7F}};
    co_frame_t boot = {.id = 0x721, .dlc = 1, .data = {0x00}};
    co_frame_t sdo = {.id = 0x5A1, .dlc = 8, .data = {0x43}};
    CHECK(is(ask("@1 unplug 2.5"), "ok"));
    CHECK(app.ports[1].unplugged && !app.ports[0].unplugged && !app.ports[2].unplugged);
    CHECK_EQ(lp_can_state(&app.ports[1]), CO_CAN_ACTIVE); /* no bus-off: counters unchanged */
    unsigned before = app.ports[1].txn;
    CHECK(co_port_can_send(&app.ports[1], &sdo)); /* taken, and lost */
    CHECK_EQ(app.ports[1].txn, before);
    CHECK_EQ(app.ports[1].tx_unplugged, 1u);
    CHECK(strstr(ask("@1 get"), " unplug=on") != NULL);
    CHECK(strstr(ask("@0 get"), "unplug") == NULL);
    (void)lp_poll(&app.ports[1], 1000u + 2499999u);
    CHECK(app.ports[1].unplugged);
    (void)lp_poll(&app.ports[1], 1000u + 2500000u);
    CHECK(!app.ports[1].unplugged); /* back by itself */
    CHECK(is(ask("@all unplug"), "ok"));
    (void)lp_poll(&app.ports[0], 1000u + 1800000000u);
    CHECK(app.ports[0].unplugged && app.ports[2].unplugged); /* until `unplug off` */
    CHECK(is(ask("@0 unplug off"), "ok"));
    CHECK(!app.ports[0].unplugged && app.ports[2].unplugged);
    CHECK(is(ask("@all unplug off"), "ok"));
    CHECK(is(ask("unplug 0"), "error: '0': not a number of seconds within 0..1800 (more than 0)"));
    CHECK(starts(ask("unplug 1800.5"), "error: '1800.5'"));
    CHECK(starts(ask("unplug -1"), "error: '-1'"));
    CHECK(is(ask("unplug 1 2"), "error: usage: unplug [SECONDS] | unplug off"));
    CHECK(strstr(ask("@all unplug x"), "'x': not a number of seconds") != NULL);
    CHECK(!app.ports[0].unplugged && !app.ports[1].unplugged && !app.ports[2].unplugged);

    CHECK(is(ask("heartbeat stop"), "ok")); /* the first instance: the JD */
    CHECK(app.ports[0].hb_stopped && !app.ports[1].hb_stopped);
    before = app.ports[0].txn;
    CHECK(co_port_can_send(&app.ports[0], &hb));
    CHECK_EQ(app.ports[0].txn, before); /* not sent */
    CHECK(co_port_can_send(&app.ports[0], &boot));
    CHECK_EQ(app.ports[0].txn, before + 1u); /* the boot-up goes */
    CHECK(co_port_can_send(&app.ports[0], &sdo));
    CHECK_EQ(app.ports[0].txn, before + 2u);
    CHECK(strstr(ask("get"), " heartbeat=stopped") != NULL);
    CHECK(is(ask("heartbeat start"), "ok"));
    CHECK(!app.ports[0].hb_stopped);
    CHECK(co_port_can_send(&app.ports[0], &hb));
    CHECK_EQ(app.ports[0].txn, before + 3u);
    CHECK(strstr(ask("get"), "heartbeat") == NULL);
    CHECK(is(ask("heartbeat"), "error: usage: heartbeat stop | heartbeat start"));
    CHECK(is(ask("heartbeat pause"), ask("heartbeat")));
    CHECK(is(ask("heartbeat stop now"), ask("heartbeat")));
    CHECK(!app.ports[0].hb_stopped);
}

static void test_selectors_all_or_none(void)
{
    make((const product_t *const[]){&dst_x730_xy30, &jd2xxx, NULL});
    co_node_start(app.nodes[0], 0);
    co_node_start(app.nodes[1], 0);
    CHECK(is(ask("0x21 set x=5"), "ok"));
    CHECK_EQ(app.inst[1].sim.values[0], 5000);
    CHECK_EQ(app.inst[0].sim.values[0], 0);
    CHECK(is(ask("@0 set y=2"), "ok"));
    CHECK_EQ(app.inst[0].sim.values[1], 2000);
    CHECK(is(ask("0x21 get"), "ok x=5.000 y=0.000 temp=25.000 nmt=pre-operational"));
    /* y is not the JD2's after the X730's fault: @all is refused whole. */
    CHECK(is(ask("@all fault sensor on"), "error: jd2xxx: jd2xxx has no simulated faults"));
    CHECK_EQ(app.inst[0].sim.faults, 0u);
    CHECK(is(ask("@all set x=7"), "ok"));
    CHECK_EQ(app.inst[0].sim.values[0], 7000);
    CHECK_EQ(app.inst[1].sim.values[0], 7000);
    CHECK(is(ask("@all set x=7000"), "error: dst-x730-xy30: 'x=7000': not a number within "
                                     "+-3600"));
    CHECK_EQ(app.inst[1].sim.values[0], 7000);
    CHECK(is(ask("@all get"), "error: get needs one node (select it: 0xID or @N)"));
    CHECK(is(ask("@2 get"), "error: no node @2 (@0..@1, or @all)"));
    CHECK(is(ask("0x55 get"), "error: no node with node-ID 0x55"));
    CHECK(starts(ask("200 get"), "error: '200': not a node-ID 1..127"));
    CHECK(is(ask("33 get"), ask("0x21 get")));
    CHECK(is(ask("@00000000000000000000000000000000001 get"),
             "error: '@0000000000000000000...': not a node selector (0xNN, NN, @N, @all)"));
}

static void test_line_assembly(void)
{
    cmd_lines_t lb = {0};
    char err[64];
    static const char in[] = "set x=4\r\n";
    unsigned ends = 0;
    for (unsigned i = 0; i + 1u < sizeof(in); i++) {
        ends += cmd_lines_put(&lb, in[i]);
    }
    CHECK_EQ(ends, 1u);
    CHECK(is(cmd_lines_take(&lb, err, sizeof(err)), "set x=4")); /* CR dropped */
    CHECK(!cmd_lines_pending(&lb));
    /* A NUL byte: rejected whole, not cut at the NUL. */
    static const char nul[] = "set x=11\0y=99\n";
    for (unsigned i = 0; i + 1u < sizeof(nul); i++) {
        (void)cmd_lines_put(&lb, nul[i]);
    }
    CHECK(cmd_lines_take(&lb, err, sizeof(err)) == NULL && is(err, "line holds a NUL byte"));
    /* Longer than CMD_LINE_MAX: rejected whole; the next line is fine. */
    for (unsigned i = 0; i < CMD_LINE_MAX + 1u; i++) {
        CHECK(!cmd_lines_put(&lb, 'a'));
    }
    CHECK(cmd_lines_pending(&lb));
    CHECK(cmd_lines_put(&lb, '\n'));
    CHECK(cmd_lines_take(&lb, err, sizeof(err)) == NULL &&
          is(err, "line longer than 255 characters"));
    /* Exactly CMD_LINE_MAX characters: taken. */
    for (unsigned i = 0; i < CMD_LINE_MAX; i++) {
        CHECK(!cmd_lines_put(&lb, i < 3u ? "get"[i] : ' '));
    }
    CHECK(cmd_lines_put(&lb, '\n'));
    const char *line = cmd_lines_take(&lb, err, sizeof(err));
    CHECK(line != NULL && strlen(line) == CMD_LINE_MAX);
    /* An answer goes out as one line, cut at CMD_REPLY_MAX bytes. */
    char out[CMD_REPLY_MAX + 1u];
    CHECK_EQ(cmd_answer_line("ok", out), 3u);
    CHECK(memcmp(out, "ok\n", 3) == 0);
    CHECK_EQ(cmd_answer_line("", out), 1u);
    CHECK_EQ(out[0], '\n');
    char big[CMD_REPLY_MAX + 20u];
    memset(big, 'x', sizeof(big) - 1u);
    big[sizeof(big) - 1u] = '\0';
    CHECK_EQ(cmd_answer_line(big, out), CMD_REPLY_MAX + 1u);
    CHECK_EQ(out[CMD_REPLY_MAX - 1u], 'x');
    CHECK_EQ(out[CMD_REPLY_MAX], '\n');
    /* A line without its newline waits (the end of input takes it). */
    CHECK(!cmd_lines_put(&lb, 'q'));
    CHECK(cmd_lines_pending(&lb));
    CHECK(is(cmd_lines_take(&lb, err, sizeof(err)), "q"));
}

/* ---- the serial line of the emulated boards ----------------------------- */

static char serial_out[256];
static size_t serial_len;

static void serial_put(char c)
{
    if (serial_len + 1u < sizeof(serial_out)) {
        serial_out[serial_len++] = c;
        serial_out[serial_len] = '\0';
    }
}

/* The serial line's answer to one line, without its CR. */
static const char *serial_ask(serial_link_t *s, const char *line)
{
    serial_len = 0;
    serial_out[0] = '\0';
    co_frame_t f;
    for (const char *c = line; *c != '\0'; c++) {
        (void)serial_link_rx(s, *c, &f, serial_put);
    }
    (void)serial_link_rx(s, '\r', &f, serial_put);
    if (serial_len > 0u && serial_out[serial_len - 1u] == '\r') {
        serial_out[--serial_len] = '\0';
    }
    return serial_out;
}

/* Every verb of the program is on the serial line or one of the verbs it
 * names as not on this target, each once; the serial line has no other. */
static void test_serial_line_verbs(void)
{
    unsigned here = 0;
    for (unsigned v = 0; v < cmd_nverbs; v++) {
        unsigned found = 0;
        for (unsigned i = 0; serial_link_verb(i) != NULL; i++) {
            found += strcmp(serial_link_verb(i), cmd_verbs[v].name) == 0;
        }
        here += found;
        for (unsigned i = 0; serial_link_absent_verb(i) != NULL; i++) {
            found += strcmp(serial_link_absent_verb(i), cmd_verbs[v].name) == 0;
        }
        if (found != 1u) {
            fprintf(stderr, "  verb '%s': in %u of the serial line's lists\n", cmd_verbs[v].name,
                    found);
        }
        CHECK_EQ(found, 1u);
    }
    unsigned nserial = 0;
    unsigned nabsent = 0;
    while (serial_link_verb(nserial) != NULL) {
        nserial++;
    }
    while (serial_link_absent_verb(nabsent) != NULL) {
        nabsent++;
    }
    CHECK_EQ(nserial + nabsent, cmd_nverbs);
    CHECK_EQ(here, nserial);
}

/* The same lines get the same answers on the serial line as in the
 * program, where the serial line has the verb: ok for ok, the same error
 * text, `get` without its "nmt=" word. The documented differences: a bad
 * `set` argument is an error on both, but the image's text names the
 * rule without the product's input list and units (an MCU image carries
 * no unit texts), and its bus-off hold is at most 60 s. */
static void test_serial_line_answers(void)
{
    static const char *const lines[] = {
        "set x=12.5 y=-3",
        "fault sensor on",
        "fault sensor maybe",
        "fault motor on",
        "get",
        "get x",
        "can passive",
        "can active",
        "can bus-off 2",
        "can off",
        "can bus-off 1 2",
        "fault sensor off",
        "set y=0.25",
        "get",
    };
    static const char *const errors_only[] = {"set x=1 y=banana", "set z=1", "set", "set x=3601"};
    make((const product_t *const[]){&dst_x730_xy30, NULL});
    serial_link_t s;
    serial_link_init(&s, &dst_x730_xy30);
    for (unsigned k = 0; k < sizeof(lines) / sizeof(lines[0]); k++) {
        char linux_answer[CMD_REPLY_MAX + 1u];
        snprintf(linux_answer, sizeof(linux_answer), "%s", ask(lines[k]));
        char *nmt = strstr(linux_answer, " nmt=");
        if (nmt != NULL) {
            *nmt = '\0';
        }
        const char *mcu = serial_ask(&s, lines[k]);
        if (strcmp(mcu, linux_answer) != 0) {
            fprintf(stderr, "  line '%s'\n", lines[k]);
        }
        CHECK(is(mcu, linux_answer));
    }
    for (unsigned k = 0; k < sizeof(errors_only) / sizeof(errors_only[0]); k++) {
        CHECK(starts(serial_ask(&s, errors_only[k]), "error: "));
    }
    CHECK(starts(ask("set x=3601"), "error: "));
    /* Numbers: the image takes plain decimals of three places at most. */
    static const char *const numbers[] = {"set x=1e1", "set x=1.2345", "can bus-off 1e1"};
    for (unsigned k = 0; k < sizeof(numbers) / sizeof(numbers[0]); k++) {
        CHECK(is(ask(numbers[k]), "ok"));
        CHECK(starts(serial_ask(&s, numbers[k]), "error: "));
    }
    CHECK(is(ask("set x=1.234"), "ok"));
    CHECK(is(serial_ask(&s, "set x=1.234"), "ok"));
    CHECK(
        is(serial_ask(&s, "can bus-off 61"), "error: '61': not a number of seconds within 0..60"));
    CHECK(is(ask("can bus-off 61"), "ok")); /* the program's limit is 1800 s */
    /* Unknown and absent verbs: the same start, the serial line's verbs. */
    CHECK(is(serial_ask(&s, "tilt 5"), "error: unknown command 'tilt' (set, fault, can, get)"));
    /* A product without faults: the image names no product ID. */
    make((const product_t *const[]){&jd1xxx, NULL});
    serial_link_init(&s, &jd1xxx);
    CHECK(is(ask("fault sensor on"), "error: jd1xxx has no simulated faults"));
    CHECK(starts(serial_ask(&s, "fault sensor on"), "error: "));
    for (unsigned i = 0; serial_link_absent_verb(i) != NULL; i++) {
        char want[96];
        snprintf(want, sizeof(want), "error: '%s' is not on this target (set, fault, can, get)",
                 serial_link_absent_verb(i));
        CHECK(is(serial_ask(&s, serial_link_absent_verb(i)), want));
    }
}

/* The program's first port, polled at t, and the serial line s at t: both
 * in state want (a macro: a failure names the caller's line). */
#define BOTH_STATES_AT(s, t, want)                                                                 \
    do {                                                                                           \
        (void)lp_poll(&app.ports[0], (t));                                                         \
        CHECK_EQ(lp_can_state(&app.ports[0]), (want));                                             \
        CHECK_EQ(serial_link_can_state((s), (t)), (want));                                         \
    } while (0)

/* Another state during a bus-off ends the hold: the controller is back
 * after the recovery alone (128 x 11 bits), in that state; the same on the
 * program's ports and on the serial line. */
static void test_bus_off_ended_by_another_state(void)
{
    make((const product_t *const[]){&jd1xxx, NULL});
    app.ports[0].kbps = 250; /* the serial line's rate: recovery 5 632 us */
    serial_link_t s;
    serial_link_init(&s, &jd1xxx);
    const uint32_t t0 = 1000u;
    const uint32_t back = t0 + 1000u + 5632u;
    CHECK(is(ask_at("can bus-off 50", t0), "ok"));
    CHECK(is(serial_ask(&s, "can bus-off 50"), "ok"));
    CHECK_EQ(serial_link_can_state(&s, t0), CO_CAN_BUSOFF);
    CHECK(is(ask_at("can warning", t0 + 1000u), "ok"));
    CHECK(is(serial_ask(&s, "can warning"), "ok"));
    CHECK_EQ(serial_link_can_state(&s, t0 + 1000u), CO_CAN_BUSOFF);
    BOTH_STATES_AT(&s, back - 1u, CO_CAN_BUSOFF);
    BOTH_STATES_AT(&s, back, CO_CAN_WARNING);
    /* A bus-off left alone comes back error active after its hold, on
     * both: the former one's cut does not shorten it. */
    CHECK(is(ask_at("can bus-off 1", back), "ok"));
    CHECK(is(serial_ask(&s, "can bus-off 1"), "ok"));
    CHECK_EQ(serial_link_can_state(&s, back), CO_CAN_BUSOFF);
    uint32_t again = back + 1000000u + 5632u;
    BOTH_STATES_AT(&s, again - 1u, CO_CAN_BUSOFF);
    BOTH_STATES_AT(&s, again, CO_CAN_ACTIVE);
    /* A state commanded in the last recovery never makes the bus-off
     * longer: it ends when it would have. */
    CHECK(is(ask_at("can bus-off", again), "ok"));
    CHECK(is(serial_ask(&s, "can bus-off"), "ok"));
    CHECK_EQ(serial_link_can_state(&s, again), CO_CAN_BUSOFF);
    CHECK(is(ask_at("can passive", again + 5000u), "ok"));
    CHECK(is(serial_ask(&s, "can passive"), "ok"));
    CHECK_EQ(serial_link_can_state(&s, again + 5000u), CO_CAN_BUSOFF);
    BOTH_STATES_AT(&s, again + 5632u, CO_CAN_PASSIVE);
}

/* `@all replay FILE` over two products: each instance takes its product's
 * table; a file one product cannot take (an input it lacks) is refused for
 * all, and nothing changes. */
static void test_replay_all_or_none(void)
{
    make((const product_t *const[]){&dst_x730_xy30, &jd2xxx, &dst_x730_xy30, NULL});
    char path[] = "/tmp/test_linux_cmd_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    static const char both[] = "t,x\n0,1\n1,3\n";
    CHECK(write(fd, both, sizeof(both) - 1u) == (ssize_t)(sizeof(both) - 1u));
    close(fd);
    char line[64];
    snprintf(line, sizeof(line), "@all replay %s", path);
    for (unsigned k = 0; k < 3u; k++) {
        sim_step(&app.inst[k].sim, 0);
    }
    CHECK(is(ask(line), "ok"));
    for (unsigned k = 0; k < 3u; k++) {
        CHECK_EQ(app.inst[k].sim.motion[0].kind, SIM_REPLAY);
        sim_step(&app.inst[k].sim, 500000u);
        CHECK_EQ(app.inst[k].sim.values[0], 2000); /* halfway from 1 to 3 */
    }
    /* temp is the JD2's alone: the DSTs refuse the file, the JD2 too. */
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    fputs("t,temp\n0,30\n", f);
    fclose(f);
    CHECK(starts(ask(line), "error: dst-x730-xy30: "));
    CHECK_EQ(app.inst[1].sim.motion[2].kind, SIM_HOLD);
    CHECK_EQ(app.inst[1].sim.values[2], 25000);
    remove(path);
}

int main(void)
{
    RUN(test_set_fault_get);
    RUN(test_verb_table);
    RUN(test_can_on_selected_nodes);
    RUN(test_unplug_and_heartbeat);
    RUN(test_selectors_all_or_none);
    RUN(test_line_assembly);
    RUN(test_serial_line_verbs);
    RUN(test_serial_line_answers);
    RUN(test_bus_off_ended_by_another_state);
    RUN(test_replay_all_or_none);
    return h_finish();
}
