/*
 * setup.c - the start; see setup.h.
 */
#include "setup.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "log.h"

/* The EEPROM file of instance k: --nvm for the --product instance, else
 * DIR/PRODUCT-0xID-IFACE.nvm with --nvm-dir (ID: the factory node-ID of
 * the instance's first node, from the command line or the product's
 * default; IFACE: its interface; a two-node product's both nodes share
 * its file, as they share the device), else none (RAM). Returns 0, or -1
 * when the name is too long. */
static int nvm_file(const options_t *o, unsigned k, uint8_t id, char *buf, size_t len,
                    const char **path)
{
    *path = NULL;
    if (k == 0u && o->prod != NULL && o->nvm_path != NULL) {
        *path = o->nvm_path;
    } else if (o->nvm_dir != NULL) {
        /* The interface is in the name: the same product at the same
         * node-ID on two buses is two devices, two files. */
        if (snprintf(buf, len, "%s/%s-0x%02X-%s.nvm", o->nvm_dir, o->spec[k].prod->id, id,
                     o->spec[k].ifn[0]) >= (int)len) {
            return -1;
        }
        *path = buf;
    }
    return 0;
}

/* Two nodes with one factory node-ID on one interface: a usage error
 * (checked before any node starts). Returns CLI_GO_ON or 2. */
static int check_clashes(const app_t *a)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        for (unsigned j = 0; j < i; j++) {
            if (strcmp(a->ifn[i], a->ifn[j]) == 0 &&
                co_node_factory_id(a->nodes[i]) == co_node_factory_id(a->nodes[j])) {
                return USAGE_ERROR("node-ID 0x%02X twice on %s (%s and %s): give each node its "
                                   "own with --node PRODUCT@ID",
                                   co_node_factory_id(a->nodes[i]), a->ifn[i],
                                   a->inst[a->node_inst[j]].prod->id,
                                   a->inst[a->node_inst[i]].prod->id);
            }
        }
    }
    return CLI_GO_ON;
}

/* The name instance k's --nvm-dir file had before the interface was in
 * it (DIR/PRODUCT-0xID.nvm), into buf; false when it does not apply. */
static bool former_nvm_name(const options_t *o, unsigned k, uint8_t id, char *buf, size_t len)
{
    return o->nvm_dir != NULL && !(k == 0u && o->prod != NULL && o->nvm_path != NULL) &&
           snprintf(buf, len, "%s/%s-0x%02X.nvm", o->nvm_dir, o->spec[k].prod->id, id) < (int)len;
}

/*
 * Open instance k's EEPROM file (read only: nothing on disk changes) and
 * hold it (nvm_file.h, lp_nvm_lock: one file, one user, also when --nvm and
 * --nvm-dir name it both). Returns CLI_GO_ON or an exit status.
 * The name before the interface was in it (DIR/PRODUCT-0xID.nvm) is
 * taken over when the new name does not exist yet, so that a stored set
 * saved by an earlier version is not silently left behind: read from
 * there now, renamed by rename_former_nvm() once the whole start has
 * worked (a failed start changes nothing on disk). *former tells.
 */
static int open_inst_nvm(app_t *a, const options_t *o, unsigned k, bool *former)
{
    app_inst_t *in = &a->inst[k];
    char err[600];
    char file[4096];
    const char *path;
    uint8_t id = co_node_factory_id(a->nodes[in->first]);
    if (nvm_file(o, k, id, file, sizeof(file), &path) != 0) {
        return USAGE_ERROR("--nvm-dir %s: too long", o->nvm_dir);
    }
    /* Messages name the option: "--nvm F: ..." or "--nvm-dir D: D/NAME: ..." */
    char opt[4200];
    if (path == file) {
        snprintf(opt, sizeof(opt), "--nvm-dir %s:", o->nvm_dir);
    } else {
        snprintf(opt, sizeof(opt), "--nvm");
    }
    char old[4096];
    struct stat st;
    *former = path == file && lstat(file, &st) != 0 && errno == ENOENT &&
              former_nvm_name(o, k, id, old, sizeof(old)) && lstat(old, &st) == 0;
    if (*former) {
        if (!S_ISREG(st.st_mode)) { /* a link too: renamed, it would point elsewhere */
            return USAGE_ERROR("--nvm-dir %s: %s (the former name of %s) is not a regular "
                               "file: move it away",
                               o->nvm_dir, old, file);
        }
        path = old;
    }
    int r = lp_nvm_open(&in->nvm, opt, path, in->nvm_mem,
                        (uint32_t)(in->prod->nodes * CO_STORE_NVM_SIZE), err, sizeof(err));
    if (r != 0) { /* a path --nvm does not take (a FIFO, ...): with the hint, as its siblings */
        return r == -2 ? USAGE_ERROR("%s", err) : cli_start_failure(CLI_FAILED, err);
    }
    if (*former) { /* held and saved under the new name from now (same directory) */
        char *slash = strrchr(in->nvm.real, '/');
        const char *base = strrchr(file, '/');
        if (slash == NULL || base == NULL ||
            (size_t)(slash - in->nvm.real) + strlen(base) >= sizeof(in->nvm.real)) {
            return USAGE_ERROR("--nvm-dir %s: too long", o->nvm_dir);
        }
        memcpy(slash, base, strlen(base) + 1u);
    }
    for (unsigned j = 0; j < k && in->nvm.path != NULL; j++) {
        const lp_nvm_t *other = &a->inst[j].nvm;
        if (other->path != NULL && strcmp(other->real, in->nvm.real) == 0) {
            return USAGE_ERROR("%s %s: the EEPROM file of %s too (one file, one instance)", opt,
                               path, o->spec[j].arg);
        }
    }
    r = lp_nvm_lock(&in->nvm, opt, path, err, sizeof(err));
    if (r != 0) {
        /* Held by another process: exit 2 as a wrong command line, but
         * without "(see --help)": the path is one --nvm takes, and the
         * message says what holds it. */
        return cli_start_failure(r == -2 ? CLI_USAGE : CLI_FAILED, err);
    }
    return CLI_GO_ON;
}

/* After a start that worked: instance k's file under its former name
 * (open_inst_nvm) gets its new name. A failure is logged; the set read
 * from the former name is in use, and the first save writes the new name. */
static void rename_former_nvm(const options_t *o, unsigned k, uint8_t id)
{
    char old[4096];
    char file[4096];
    const char *path;
    if (!former_nvm_name(o, k, id, old, sizeof(old)) ||
        nvm_file(o, k, id, file, sizeof(file), &path) != 0) {
        return;
    }
    if (rename(old, file) != 0) {
        lp_log("warning: EEPROM file %s (the former name) not renamed %s: %s: its set is in use; "
               "the first save writes the new name",
               old, file, strerror(errno));
        return;
    }
    lp_log("EEPROM file %s renamed %s (the interface is in the name now)", old, file);
}

/* Open the sockets and LEDs of instance k's nodes. Returns CLI_GO_ON or 1. */
static int open_inst_ports(app_t *a, const options_t *o, unsigned k, uint32_t t)
{
    app_inst_t *in = &a->inst[k];
    char err[600];
    for (unsigned i = 0; i < in->prod->nodes; i++) {
        unsigned g = in->first + i;
        if (lp_open(&a->ports[g], a->ifn[g], g, &in->nvm, t, err, sizeof(err)) != 0) {
            /* The option that named the interface: --node P/IFACE, or --iface */
            const node_spec_t *n = &o->spec[k];
            bool node_opt = n->iface != NULL && !(k == 0u && o->prod != NULL);
            const char *given = node_opt ? n->iface : o->iface;
            char msg[sizeof(err) + 300];
            if (node_opt) {
                snprintf(msg, sizeof(msg), "--node %s: %s: %s", n->arg, a->ifn[g], err);
            } else if (strcmp(given, a->ifn[g]) == 0) {
                snprintf(msg, sizeof(msg), "--iface %s: %s", given, err);
            } else {
                snprintf(msg, sizeof(msg), "--iface %s: %s: %s", given, a->ifn[g], err);
            }
            return cli_start_failure(1, msg);
        }
        if (leds_open(&a->leds[g], g == 0 ? o->led_chip : NULL, o->led_green, o->led_red, err,
                      sizeof(err)) != 0) {
            return cli_start_failure(1, err);
        }
    }
    return CLI_GO_ON;
}

/* Instance k's program download (--program-download): the loader's
 * dictionary on its first node, its program area beside its EEPROM file.
 * Returns CLI_GO_ON or 1. */
static int open_inst_prog(app_t *a, unsigned k)
{
    app_inst_t *in = &a->inst[k];
    char err[600];
    if (lp_prog_build(&in->prog, co_cfg(a->nodes[in->first]), err, sizeof(err)) != 0 ||
        lp_prog_open(&in->prog, in->prod->id, in->nvm.real, &a->nodes[in->first], in->prod->nodes,
                     err, sizeof(err)) != 0) {
        return cli_start_failure(CLI_FAILED, err);
    }
    in->progdl = true;
    for (unsigned i = 0; i < in->prod->nodes; i++) {
        a->ports[in->first + i].prog = &in->prog;
        a->ports[in->first + i].progdl = &in->prog.pd;
    }
    return CLI_GO_ON;
}

/* Instance k of the command line, created (not started). */
static int add_inst(app_t *a, const options_t *o, unsigned k)
{
    const node_spec_t *n = &o->spec[k];
    if (app_add(a, n->prod, n->ifn, n->id, o->serial) < 0) {
        return cli_start_failure(CLI_FAILED, "product instance too large");
    }
    sim_seed(&a->inst[k].sim, o->seed + k); /* each instance its own noise */
    return CLI_GO_ON;
}

int setup_run(app_t *a, loop_t *l, const options_t *o)
{
    memset(a, 0, sizeof(*a));
    a->tx.fd = -1;
    if (o->log_path != NULL) {
        FILE *lf = fopen(o->log_path, "a");
        if (lf == NULL) {
            return USAGE_ERROR("--log %s: %s", o->log_path, strerror(errno));
        }
        lp_log_open(lf);
    }
    struct stat in_st;
    if (fstat(STDIN_FILENO, &in_st) == 0 && S_ISDIR(in_st.st_mode)) {
        /* read() would fail (EISDIR) at once: an end of input nobody meant */
        return USAGE_ERROR("standard input is a directory (give the commands on a pipe, a "
                           "terminal or a file, or < /dev/null)");
    }
    if (o->nvm_dir != NULL) {
        struct stat st;
        if (stat(o->nvm_dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
            return USAGE_ERROR("--nvm-dir %s: not a directory", o->nvm_dir);
        }
    }
    for (unsigned k = 0; k < o->nspec; k++) {
        int r = add_inst(a, o, k);
        if (r != CLI_GO_ON) {
            return r;
        }
    }
    int rc = check_clashes(a);
    if (rc != CLI_GO_ON) {
        return rc;
    }
    bool former[APP_MAX_NODES] = {false};
    for (unsigned k = 0; k < a->ninst; k++) {
        rc = open_inst_nvm(a, o, k, &former[k]);
        if (rc != CLI_GO_ON) {
            return rc;
        }
    }
    uint32_t t = loop_now_us();
    for (unsigned k = 0; k < a->ninst; k++) {
        rc = open_inst_ports(a, o, k, t);
        if (rc != CLI_GO_ON) {
            return rc;
        }
    }
    lp_udp_share(a->ports, a->nnodes); /* one receiving socket a udp_multicast group */
    for (unsigned k = 0; k < a->ninst && o->progdl; k++) {
        rc = open_inst_prog(a, k);
        if (rc != CLI_GO_ON) {
            return rc;
        }
    }
    /* Every node on SocketCAN sends through one socket (can_port.h,
     * lp_tx_t); a node on a udp_multicast bus through its own. */
    char err[600];
    bool socketcan = false;
    for (unsigned i = 0; i < a->nnodes; i++) {
        socketcan = socketcan || !a->ports[i].udp;
    }
    if (socketcan && lp_tx_open(&a->tx, err, sizeof(err)) != 0) {
        return cli_start_failure(CLI_FAILED, err);
    }
    int r = loop_open(l, a, o->control, o->quit_on_eof, err, sizeof(err));
    if (r != 0) {
        return r == -2 ? USAGE_ERROR("%s", err) : cli_start_failure(CLI_FAILED, err);
    }
    /* Nothing can fail the start any more: the former names go now. */
    for (unsigned k = 0; k < a->ninst; k++) {
        if (former[k]) {
            rename_former_nvm(o, k, co_node_factory_id(a->nodes[a->inst[k].first]));
        }
    }
    app_sample(a, t);
    t = loop_now_us();
    app_start(a, t);
    app_log_store_status(a);
    loop_start(l, t);
    return CLI_GO_ON;
}
