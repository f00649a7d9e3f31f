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

static pthread_mutex_t job_lock = PTHREAD_MUTEX_INITIALIZER; /* one job at a time */
static pthread_mutex_t mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t cv_start = PTHREAD_COND_INITIALIZER;
static pthread_cond_t cv_done = PTHREAD_COND_INITIALIZER;
static int threads = 0;  /* configured count (0: not yet read) */
static int started = 0;  /* workers running */
static long generation = 0;
static struct {
    pool_task fn;
    void *ctx;
    long n, grain;
    long next;  /* atomic: first item of the next chunk */
    int wanted; /* workers taking part */
    int done;   /* workers finished */
} job;

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

int pool_threads(void)
{
    if (threads == 0)
        threads = default_threads();
    return threads;
}

void pool_set_threads(int n)
{
    threads = n < 1 ? 1 : (n > POOL_MAX ? POOL_MAX : n);
}

static void run_chunks(void)
{
    for (;;) {
        long b = __atomic_fetch_add(&job.next, job.grain, __ATOMIC_RELAXED);
        if (b >= job.n)
            return;
        long e = b + job.grain < job.n ? b + job.grain : job.n;
        job.fn(job.ctx, b, e);
    }
}

static void *worker_main(void *arg)
{
    int id = (int)(long)arg; /* 1, 2, ... */
    long seen = 0;
    pthread_mutex_lock(&mu);
    for (;;) {
        while (generation == seen)
            pthread_cond_wait(&cv_start, &mu);
        seen = generation;
        if (id > job.wanted)
            continue;
        pthread_mutex_unlock(&mu);
        run_chunks();
        pthread_mutex_lock(&mu);
        if (++job.done == job.wanted)
            pthread_cond_signal(&cv_done);
    }
    return NULL;
}

static void atfork_prepare(void) { pthread_mutex_lock(&job_lock); }
static void atfork_parent(void) { pthread_mutex_unlock(&job_lock); }
static void atfork_child(void)
{
    /* the workers did not come along: start afresh */
    pthread_mutex_t m0 = PTHREAD_MUTEX_INITIALIZER;
    pthread_cond_t c0 = PTHREAD_COND_INITIALIZER;
    job_lock = m0;
    mu = m0;
    cv_start = c0;
    cv_done = c0;
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
        fn(ctx, 0, n); /* one chunk, one thread, or another job is running */
        return;
    }
    if (!registered) {
        pthread_atfork(atfork_prepare, atfork_parent, atfork_child);
        registered = 1;
    }
    pthread_mutex_lock(&mu);
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
    job.fn = fn;
    job.ctx = ctx;
    job.n = n;
    job.grain = grain;
    job.next = 0;
    job.wanted = want;
    job.done = 0;
    generation++;
    pthread_cond_broadcast(&cv_start);
    pthread_mutex_unlock(&mu);
    run_chunks();
    pthread_mutex_lock(&mu);
    while (job.done < job.wanted)
        pthread_cond_wait(&cv_done, &mu);
    pthread_mutex_unlock(&mu);
    pthread_mutex_unlock(&job_lock);
}
#endif
