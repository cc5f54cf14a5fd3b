/*
 * size_switches.c - the headers that hold the build-time size switches
 * (CO_TPDO_MAX, CO_SDO_BUF, CO_EMCY_ACTIVE_MAX, CO_EMCY_HIST_MAX,
 * CO_INCL_CIRCULAR) and the store's fixed sizes. tests/config/
 * size_switches.cmake compiles this file (syntax only) with each switch
 * out of range and expects the build to stop with that switch's #error,
 * and with the defaults and a shipped image's sizes expects it to build.
 */
#include "co_incl.h"
#include "co_node.h"
