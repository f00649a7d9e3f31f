/* The AVX2 + FMA copy of robokin's kernels (see module.c); setup.py compiles it with
 * -mavx2 -mfma, and robokin._native imports it only on a CPU that has both. */
#define MODULE_NAME "_avx2"
#define MODULE_INIT PyInit__avx2
#define ISA_NAME "avx2+fma"
#define ISA_RUNS cpu_runs_avx2_fma()
#include "module.c"
