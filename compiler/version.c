/* version.c — splatc_version (splatc.h): the version CMake gave the
 * library (SPLATC_VERSION, the project's version). */
#include "splatc.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

const char *splatc_version(void) { return SPLATC_VERSION; }
