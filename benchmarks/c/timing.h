/* The shared timing harness of rpr3gen's C benchmarks (clock, warm-up, repeats, percentiles).
 *
 * Every C benchmark includes this one header. A measurement is a loop body run over `n`
 * samples, `repeats` times after one untimed warm-up pass; each pass is timed with
 * CLOCK_MONOTONIC and gives ns per sample; the passes' minimum, median (p50) and p99 are
 * reported as one JSON line, {"name": ..., "min": ..., "p50": ..., "p99": ..., "repeats": ...},
 * which benchmarks/run.py collects. Latencies of single events (ticks) use the same
 * percentiles through timing_summary.
 */
#ifndef RPR3_BENCH_TIMING_H
#define RPR3_BENCH_TIMING_H

#define _POSIX_C_SOURCE 199309L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Nanoseconds of CLOCK_MONOTONIC (the vDSO's TSC read on Linux, about 20 ns). */
static double timing_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static int timing_compare(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts values[0..n) in place and returns the value of rank p (0..1) among them: rank
 * floor(p (n - 1)), so p50 of an even count is the lower middle, as control_loop.c picks it. */
static double timing_percentile(double *values, size_t n, double p)
{
    qsort(values, n, sizeof *values, timing_compare);
    return values[(size_t)(p * (double)(n - 1))];
}

/* Prints one result line: min, p50, p99 of values[0..n) (sorted in place), with a unit. */
static void timing_summary(const char *name, const char *unit, double *values, size_t n)
{
    const double p50 = timing_percentile(values, n, 0.5);
    printf("{\"name\": \"%s\", \"unit\": \"%s\", \"min\": %.4g, \"p50\": %.4g, \"p99\": %.4g, "
           "\"max\": %.4g, \"repeats\": %zu}\n",
           name, unit, values[0], p50, values[(size_t)(0.99 * (double)(n - 1))], values[n - 1],
           n);
}


#endif
