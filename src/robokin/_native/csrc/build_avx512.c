/* The AVX-512 copy of robokin's kernels (see module.c): 8 lanes, 32 vector
 * registers; setup.py compiles it with -mavx512f -mavx512dq -mavx512vl -mavx2 -mfma,
 * and robokin._native imports it only on a CPU that has them. */
#define MODULE_NAME "_avx512"
#define MODULE_INIT PyInit__avx512
#define ISA_NAME "avx512"
#define ISA_RUNS cpu_runs_avx512()
#include "module.c"
