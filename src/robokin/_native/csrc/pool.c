/* The thread pool of pool.h. */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* sched_getaffinity */
#endif
#include "pool.h"

#include <stdlib.h>

#define POOL_MAX 64

#ifdef _WIN32
int pool_threads(void) { return 1; }
void pool_set_threads(int n) { (void)n; }
void pool_for(long n, long grain, pool_task fn, void *ctx)
{
    if (n > 0)
        fn(ctx, 0, n);
    (void)grain;
}
#else
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

static pthread_mutex_t job_lock = PTHREAD_MUTEX_INITIALIZER; /* one pool_job at a time */
static pthread_mutex_t pool_mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t cv_start = PTHREAD_COND_INITIALIZER;
static pthread_cond_t cv_done = PTHREAD_COND_INITIALIZER;
static int pool_n = 0;  /* configured count (0: not yet read) */
static int started = 0;  /* workers running */
static long generation = 0;
static struct {
    pool_task fn;
    void *ctx;
    long n, grain;
    long next;  /* atomic: first item of the next chunk */
    int wanted; /* workers taking part */
    int done;   /* workers finished */
} pool_job;

static int default_threads(void)
{
    const char *env = getenv("ROBOKIN_NUM_THREADS");
    if (env != NULL && *env) {
        int k = atoi(env);
        if (k >= 1)
            return k < POOL_MAX ? k : POOL_MAX;
    }
#ifdef CPU_COUNT
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof(set), &set) == 0) {
        int k = CPU_COUNT(&set);
        if (k >= 1)
            return k < POOL_MAX ? k : POOL_MAX;
    }
#endif
    long k = sysconf(_SC_NPROCESSORS_ONLN);
    return k < 1 ? 1 : (k < POOL_MAX ? (int)k : POOL_MAX);
}

/* pool_n is read by pool_for with the GIL released and written by
 * set_num_threads with it held (another thread may be in pool_for): atomic. */
int pool_threads(void)
{
    int k = __atomic_load_n(&pool_n, __ATOMIC_RELAXED);
    if (k == 0) {
        int zero = 0, d = default_threads();
        /* first use: the default, unless another thread set a count meanwhile */
        if (__atomic_compare_exchange_n(&pool_n, &zero, d, 0, __ATOMIC_RELAXED,
                                        __ATOMIC_RELAXED))
            k = d;
        else
            k = zero;
    }
    return k;
}

void pool_set_threads(int n)
{
    __atomic_store_n(&pool_n, n < 1 ? 1 : (n > POOL_MAX ? POOL_MAX : n), __ATOMIC_RELAXED);
}

static void run_chunks(void)
{
    for (;;) {
        long b = __atomic_fetch_add(&pool_job.next, pool_job.grain, __ATOMIC_RELAXED);
        if (b >= pool_job.n)
            return;
        long e = b + pool_job.grain < pool_job.n ? b + pool_job.grain : pool_job.n;
        pool_job.fn(pool_job.ctx, b, e);
    }
}

static void *worker_main(void *arg)
{
    int id = (int)(long)arg; /* 1, 2, ... */
    long seen = 0;
    pthread_mutex_lock(&pool_mu);
    for (;;) {
        while (generation == seen)
            pthread_cond_wait(&cv_start, &pool_mu);
        seen = generation;
        if (id > pool_job.wanted)
            continue;
        pthread_mutex_unlock(&pool_mu);
        run_chunks();
        pthread_mutex_lock(&pool_mu);
        if (++pool_job.done == pool_job.wanted)
            pthread_cond_signal(&cv_done);
    }
    return NULL;
}

/* fork: the parent holds both locks across fork() (no job runs, no worker is
 * between two states), so the child gets them unlocked by their owner (the
 * forking thread, its only thread) and fresh condition variables; its workers did
 * not come along, so it starts its own on first use. */
static void atfork_prepare(void)
{
    pthread_mutex_lock(&job_lock);
    pthread_mutex_lock(&pool_mu);
}

static void atfork_parent(void)
{
    pthread_mutex_unlock(&pool_mu);
    pthread_mutex_unlock(&job_lock);
}

static void atfork_child(void)
{
    pthread_mutex_unlock(&pool_mu);
    pthread_mutex_unlock(&job_lock);
    pthread_cond_init(&cv_start, NULL);
    pthread_cond_init(&cv_done, NULL);
    started = 0;
    generation = 0;
}

void pool_for(long n, long grain, pool_task fn, void *ctx)
{
    static int registered = 0;
    if (n <= 0)
        return;
    if (grain < 1)
        grain = 1;
    long chunks = (n + grain - 1) / grain;
    int want = pool_threads() - 1;
    if (want > chunks - 1)
        want = (int)(chunks - 1);
    if (want <= 0 || pthread_mutex_trylock(&job_lock) != 0) {
        fn(ctx, 0, n); /* one chunk, one thread, or another pool_job is running */
        return;
    }
    if (!registered) {
        pthread_atfork(atfork_prepare, atfork_parent, atfork_child);
        registered = 1;
    }
    pthread_mutex_lock(&pool_mu);
    while (started < want) {
        pthread_t th;
        pthread_attr_t attr;
        pthread_attr_init(&attr);
        pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
        int err = pthread_create(&th, &attr, worker_main, (void *)(long)(started + 1));
        pthread_attr_destroy(&attr);
        if (err != 0)
            break;
        started++;
    }
    if (want > started)
        want = started;
    pool_job.fn = fn;
    pool_job.ctx = ctx;
    pool_job.n = n;
    pool_job.grain = grain;
    pool_job.next = 0;
    pool_job.wanted = want;
    pool_job.done = 0;
    generation++;
    pthread_cond_broadcast(&cv_start);
    pthread_mutex_unlock(&pool_mu);
    run_chunks();
    pthread_mutex_lock(&pool_mu);
    while (pool_job.done < pool_job.wanted)
        pthread_cond_wait(&cv_done, &pool_mu);
    pthread_mutex_unlock(&pool_mu);
    pthread_mutex_unlock(&job_lock);
}
#endif
