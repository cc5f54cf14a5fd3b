/*
 * main.c - canopen-sensor: runs products of od/ as a process on SocketCAN
 * interfaces, one (--product) or many instances (--node), each with its
 * own nodes, inputs and EEPROM file. Parse the command line (cli.h), set
 * up (setup.h), run the event loop (loop.h), shut down (app.h); the exit
 * statuses are cli.h's.
 */
#include <signal.h>

#include "app.h"
#include "cli.h"
#include "log.h"
#include "loop.h"
#include "setup.h"

int main(int argc, char **argv)
{
    /* Before anything else: the stop signals are blocked from the first
     * instruction of main, and wait in the kernel until the loop reads
     * them (signalfd), so that a SIGTERM while the program starts (the
     * sockets, the EEPROM files) is a clean stop (exit 0) like one a
     * minute later, not the default action (killed, 143). One during a
     * failing start is dropped with the process (the failure's status).
     * Only a signal before main (exec and the dynamic loader: about 1 ms
     * on a PC, up to 20 ms under User-Mode Linux) meets the default
     * action; a parent that blocks them for the child avoids that too
     * (the mask is inherited through exec). */
    sigset_t sigs;
    loop_stop_signals(&sigs);
    sigprocmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);
    lp_log_start(); /* the log's time zero */
    /* static: 127 nodes' instances, sockets and EEPROM mirrors (about a
     * megabyte) are better off the stack; main is their only user. */
    static options_t o;
    int rc = cli_parse(argc, argv, &o);
    if (rc != CLI_GO_ON) {
        return rc;
    }
    if (o.eds) {
        return cli_print_eds(o.prod, o.progdl);
    }
    static app_t a;
    static loop_t l;
    rc = setup_run(&a, &l, &o);
    if (rc != CLI_GO_ON) {
        app_release_nvm(&a); /* a failed start leaves no hold file behind */
        return rc;
    }
    rc = loop_run(&l);
    app_shut_down(&a);
    loop_close(&l);
    return rc;
}
