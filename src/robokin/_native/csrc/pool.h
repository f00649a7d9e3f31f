/*
 * A small persistent thread pool for the batch kernels (the GIL is released while
 * it runs). pool_for(n, grain, fn, ctx) cuts [0, n) into chunks of `grain` items
 * that the calling thread and up to pool_threads() - 1 workers take from a shared
 * counter; it returns when every chunk is done. Results never depend on the
 * number of threads: each item is computed by the same code whoever takes it.
 *
 * One job runs at a time: a call made while another thread's job runs does its
 * work on its own thread. Workers start on first use and survive between calls;
 * after fork() the child starts its own (pthread_atfork).
 */
#ifndef ROBOKIN_POOL_H
#define ROBOKIN_POOL_H

typedef void (*pool_task)(void *ctx, long begin, long end);

int pool_threads(void);
void pool_set_threads(int n);
void pool_for(long n, long grain, pool_task fn, void *ctx);

#endif
