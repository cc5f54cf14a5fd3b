/*
 * progdl_app.c - CiA 302-3 program download, the application side: the
 * write hook of 1F51h:1 in a product image that a bootloader runs
 * (CO_PROGDL_APP_ENTRIES, co_progdl.h). A file of its own: an application
 * links this one function and nothing of the loader (progdl.c).
 */
#include "co_progdl.h"

#include "co_port.h"

/* Stop hands over to the bootloader, which takes the download (the board
 * resets into it once the answer has left); the application is started
 * already; a clear is the bootloader's; a reset (2) CiA 302-3 lets a
 * device refuse. The entry's limits refuse 4..255 (06090031h). */
co_res_t co_progdl_app_write_control(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    (void)e;
    if (value == CO_PROGDL_STOPPED) {
        co_port_prog_handover(node->port);
    }
    return value <= CO_PROGDL_STARTED ? CO_OK : CO_E_STATE;
}
