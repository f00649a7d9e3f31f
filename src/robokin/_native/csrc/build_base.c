/* The baseline copy of robokin's kernels (see module.c). */
#define MODULE_NAME "_base"
#define MODULE_INIT PyInit__base
#define ISA_NAME "baseline"
#define ISA_RUNS 1
#include "module.c"
