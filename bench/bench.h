/* bench/bench.h - the clocks and the machine description shared by the
 * benchmarks (header-only, like plot.h; not installed, not part of the
 * library). Each benchmark prints its own header lines from these:
 *
 *   double w0 = bench_wall(), c0 = bench_cpu();
 *   ... the measured work ...
 *   double wall = bench_wall() - w0, cpu = bench_cpu() - c0;
 *
 *   char cpu[256];
 *   int nproc = bench_cpu_model(cpu, sizeof cpu);   // "model name", CPUs listed
 *   double la[3];
 *   bench_loadavg(la);
 *
 * Include it after defining _POSIX_C_SOURCE 200809L (or _GNU_SOURCE) before
 * the first #include, as every benchmark does. */
#ifndef ODHS_BENCH_BENCH_H
#define ODHS_BENCH_BENCH_H

#include <stdio.h>
#include <string.h>
#include <time.h>

#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#error "bench.h needs _POSIX_C_SOURCE 200809L (or _GNU_SOURCE) defined before the first #include"
#endif

/* wall-clock seconds from an arbitrary origin (CLOCK_MONOTONIC): wall times,
 * budgets and deadlines */
static inline double bench_wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU seconds of the process, all its threads, user and system
 * (CLOCK_PROCESS_CPUTIME_ID): the measurements, as the machine may be
 * shared with other jobs */
static inline double bench_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The first "model name" of /proc/cpuinfo into buf ("unknown" without one).
 * Returns the number of CPUs the file lists ("processor" lines; 0 when it
 * cannot be read). */
static inline int bench_cpu_model(char *buf, size_t len)
{
    int nproc = 0, found = 0;
    snprintf(buf, len, "unknown");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f) return 0;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (!found && !strncmp(line, "model name", 10)) {
            found = 1;
            char *c = strchr(line, ':');
            if (c) {
                snprintf(buf, len, "%s", c + 2);
                buf[strcspn(buf, "\n")] = 0;
            }
        }
        if (!strncmp(line, "processor", 9)) nproc++;
    }
    fclose(f);
    return nproc;
}

/* the load averages over 1, 5 and 15 minutes (/proc/loadavg; zeros when it
 * cannot be read) */
static inline void bench_loadavg(double la[3])
{
    la[0] = la[1] = la[2] = 0.0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (!f) return;
    if (fscanf(f, "%lf %lf %lf", &la[0], &la[1], &la[2]) != 3) la[0] = la[1] = la[2] = 0.0;
    fclose(f);
}

#endif /* ODHS_BENCH_BENCH_H */
