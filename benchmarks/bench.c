/* C timing harness of rpr3gen's generated inverse dynamics (run by benchmarks/run.py,
 * through benchmarks/rpr3bench/charness.py).
 *
 * Build (from the repository root), as the harness does (the runtime's flags):
 *   cc -std=c99 -O3 -fno-math-errno -fno-trapping-math -march=native -mno-fma \
 *      -I generated/revolute benchmarks/bench.c generated/revolute/rpr3.c -lm -o bench
 *
 * Usage:
 *   bench PARAMS INPUTS N REPEATS [MODE]
 *     PARAMS   text file of "name value" lines (the output of `rpr3gen params`), any order;
 *              every name of rpr3_param_names must appear
 *     INPUTS   raw native-endian float64: q (N x 3), then qd (N x 3), then qdd (N x 3)
 *     N        number of samples in INPUTS
 *     REPEATS  timed repeats of every loop; the best (smallest) time is reported
 *     MODE     "all" (default), "floor" (only the floor loops) or "batch" (only the batch
 *              over all N samples, for profilers)
 *
 * Prints "key value" lines; times are ns per sample of the best repeat (CLOCK_MONOTONIC).
 * The repeats of the different loops are interleaved so that they share machine conditions.
 *
 *   floor_ns            the transcendental floor: per sample one sin and one cos of phi, and per
 *                       leg the sqrt and the atan2 of the leg vector (3 sqrt, 3 atan2), with the
 *                       few multiply-adds that form their arguments; results are summed into an
 *                       accumulator that is printed, so nothing can be removed
 *   floor_gen_ns        the floor plus the sin and cos of alpha_A, alpha_B, alpha_C per sample
 *                       (4 sin, 4 cos, 3 sqrt, 3 atan2): what parameter trigonometry evaluated
 *                       per sample costs, as earlier generated code did
 *   single_ns           rpr3_inverse_dynamics called once per sample, out one buffer of
 *                       RPR3_NUM_OUTPUTS doubles
 *   batch_ns            rpr3_inverse_dynamics_batch over all N samples (N x RPR3_NUM_OUTPUTS
 *                       output)
 *   batch_small_ns      rpr3_inverse_dynamics_batch over the first 1000 samples, repeated to
 *                       cover N samples: the output stays in cache (no memory streaming)
 */
#define _POSIX_C_SOURCE 199309L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rpr3.h"

#define SMALL_BATCH 1000

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int param_index(const char *name)
{
    int k;
    for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
        if (strcmp(rpr3_param_names[k], name) == 0) {
            return k;
        }
    }
    return -1;
}

static int read_params(const char *path, double *params)
{
    char name[64];
    double value;
    int seen[RPR3_NUM_PARAMS] = {0};
    int k;
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        fprintf(stderr, "bench: cannot open %s\n", path);
        return 1;
    }
    while (fscanf(f, "%63s %lf", name, &value) == 2) {
        k = param_index(name);
        if (k >= 0) {
            params[k] = value;
            seen[k] = 1;
        }
    }
    fclose(f);
    for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
        if (!seen[k]) {
            fprintf(stderr, "bench: parameter %s missing from %s\n", rpr3_param_names[k], path);
            return 1;
        }
    }
    return 0;
}

/* FLOOR BEGIN: rpr3bench/charness.py looks for compiler vectorisation remarks between these
 * markers. */

/* One sin and one cos of phi, and per leg the length (sqrt) and direction (atan2) of the leg
 * vector A1 -> A3 = G + R(phi) p - A1, as the generated code forms them. */
static double floor_loop(const double *params, size_t n, const double *q)
{
    const double xA1 = params[0], yA1 = params[1], xB1 = params[2], yB1 = params[3];
    const double xC1 = params[4], yC1 = params[5], xA3 = params[6], yA3 = params[7];
    const double xB3 = params[8], yB3 = params[9], xC3 = params[10], yC3 = params[11];
    double acc = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        const double x = q[3 * i], y = q[3 * i + 1], phi = q[3 * i + 2];
        const double c = cos(phi), s = sin(phi);
        const double lxA = x + c * xA3 - s * yA3 - xA1, lyA = y + c * yA3 + s * xA3 - yA1;
        const double lxB = x + c * xB3 - s * yB3 - xB1, lyB = y + c * yB3 + s * xB3 - yB1;
        const double lxC = x + c * xC3 - s * yC3 - xC1, lyC = y + c * yC3 + s * xC3 - yC1;
        const double lengths = sqrt(lxA * lxA + lyA * lyA) + sqrt(lxB * lxB + lyB * lyB)
                               + sqrt(lxC * lxC + lyC * lyC);
        const double angles = atan2(lyA, lxA) + atan2(lyB, lxB) + atan2(lyC, lxC);
        acc += lengths + angles;
    }
    return acc;
}

/* The floor plus the sin and cos of the three alpha parameters per sample; "+ 0.0 * phi" keeps
 * the compiler from hoisting them out of the loop (it cannot fold 0.0 * phi under IEEE rules),
 * so each sample pays for them as a kernel that evaluates them per sample would. */
static double floor_generated_loop(const double *params, size_t n, const double *q)
{
    const double xA1 = params[0], yA1 = params[1], xB1 = params[2], yB1 = params[3];
    const double xC1 = params[4], yC1 = params[5], xA3 = params[6], yA3 = params[7];
    const double xB3 = params[8], yB3 = params[9], xC3 = params[10], yC3 = params[11];
    const double aA = params[12], aB = params[13], aC = params[14];
    double acc = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        const double x = q[3 * i], y = q[3 * i + 1], phi = q[3 * i + 2];
        const double z = 0.0 * phi;
        const double c = cos(phi), s = sin(phi);
        const double lxA = x + c * xA3 - s * yA3 - xA1, lyA = y + c * yA3 + s * xA3 - yA1;
        const double lxB = x + c * xB3 - s * yB3 - xB1, lyB = y + c * yB3 + s * xB3 - yB1;
        const double lxC = x + c * xC3 - s * yC3 - xC1, lyC = y + c * yC3 + s * xC3 - yC1;
        const double lengths = sqrt(lxA * lxA + lyA * lyA) + sqrt(lxB * lxB + lyB * lyB)
                               + sqrt(lxC * lxC + lyC * lyC);
        const double angles = atan2(lyA, lxA) + atan2(lyB, lxB) + atan2(lyC, lxC);
        const double alphas = (cos(aA + z) + sin(aA + z)) + (cos(aB + z) + sin(aB + z))
                              + (cos(aC + z) + sin(aC + z));
        acc += lengths + angles + alphas;
    }
    return acc;
}

/* FLOOR END */

/* Index of an output by name (the checksums sum m10_A); 0 if there is none by that name. */
static int output_index(const char *name)
{
    int k;
    for (k = 0; k < RPR3_NUM_OUTPUTS; ++k) {
        if (strcmp(rpr3_output_names[k], name) == 0) {
            return k;
        }
    }
    return 0;
}

static double single_loop(const double *params, size_t n, const double *q, const double *qd,
                          const double *qdd, double *out, int column, size_t *failed)
{
    double acc = 0.0;
    size_t i;
    *failed = 0;
    for (i = 0; i < n; ++i) {
        if (rpr3_inverse_dynamics(params, q + 3 * i, qd + 3 * i, qdd + 3 * i, out) != RPR3_OK) {
            ++*failed;
        }
        acc += out[column];
    }
    return acc;
}

static double column_sum(const double *out, size_t n, int column)
{
    double acc = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        acc += out[i * RPR3_NUM_OUTPUTS + column];
    }
    return acc;
}

static void keep_best(double *best, double elapsed)
{
    if (*best < 0.0 || elapsed < *best) {
        *best = elapsed;
    }
}

int main(int argc, char **argv)
{
    double params[RPR3_NUM_PARAMS];
    double single_out[RPR3_NUM_OUTPUTS];
    double *inputs, *out, *small_out;
    const double *q, *qd, *qdd;
    double best_floor = -1.0, best_floor_gen = -1.0, best_single = -1.0, best_batch = -1.0;
    double best_small = -1.0;
    double acc_floor = 0.0, acc_floor_gen = 0.0, acc_single = 0.0, t0;
    size_t n, nsmall, k, failed_single = 0, failed_batch = 0, failed_small = 0;
    int repeats, r, floor_only, batch_only, column = output_index("m10_A");
    FILE *f;

    if (argc < 5 || argc > 6) {
        fprintf(stderr, "usage: %s PARAMS INPUTS N REPEATS [all|floor|batch]\n", argv[0]);
        return 2;
    }
    n = (size_t)strtoull(argv[3], NULL, 10);
    repeats = atoi(argv[4]);
    floor_only = argc == 6 && strcmp(argv[5], "floor") == 0;
    batch_only = argc == 6 && strcmp(argv[5], "batch") == 0;
    if (n == 0 || repeats < 1 || read_params(argv[1], params) != 0) {
        return 2;
    }
    inputs = malloc(9 * n * sizeof(double));
    f = fopen(argv[2], "rb");
    if (inputs == NULL || f == NULL || fread(inputs, sizeof(double), 9 * n, f) != 9 * n) {
        fprintf(stderr, "bench: cannot read %zu samples from %s\n", n, argv[2]);
        return 2;
    }
    fclose(f);
    q = inputs;
    qd = inputs + 3 * n;
    qdd = inputs + 6 * n;
    nsmall = n < SMALL_BATCH ? n : SMALL_BATCH;
    out = floor_only ? NULL : malloc(n * RPR3_NUM_OUTPUTS * sizeof(double));
    small_out = floor_only ? NULL : malloc(nsmall * RPR3_NUM_OUTPUTS * sizeof(double));
    if (!floor_only && (out == NULL || small_out == NULL)) {
        fprintf(stderr, "bench: out of memory\n");
        return 2;
    }
    if (!floor_only) { /* touch every page before timing */
        memset(out, 0, n * RPR3_NUM_OUTPUTS * sizeof(double));
        memset(small_out, 0, nsmall * RPR3_NUM_OUTPUTS * sizeof(double));
    }

    for (r = 0; r < repeats; ++r) {
        if (batch_only) {
            t0 = now_s();
            failed_batch = rpr3_inverse_dynamics_batch(params, n, q, qd, qdd, out);
            keep_best(&best_batch, now_s() - t0);
            continue;
        }
        t0 = now_s();
        acc_floor = floor_loop(params, n, q);
        keep_best(&best_floor, now_s() - t0);

        t0 = now_s();
        acc_floor_gen = floor_generated_loop(params, n, q);
        keep_best(&best_floor_gen, now_s() - t0);

        if (floor_only) {
            continue;
        }
        t0 = now_s();
        acc_single = single_loop(params, n, q, qd, qdd, single_out, column, &failed_single);
        keep_best(&best_single, now_s() - t0);

        t0 = now_s();
        failed_batch = rpr3_inverse_dynamics_batch(params, n, q, qd, qdd, out);
        keep_best(&best_batch, now_s() - t0);

        failed_small = 0;
        t0 = now_s();
        for (k = 0; k + nsmall <= n; k += nsmall) {
            failed_small += rpr3_inverse_dynamics_batch(params, nsmall, q, qd, qdd, small_out);
        }
        keep_best(&best_small, now_s() - t0);
    }

    if (batch_only) {
        printf("batch_ns %.3f\n", 1e9 * best_batch / (double)n);
        printf("batch_failed %zu\n", failed_batch);
        free(inputs);
        free(out);
        free(small_out);
        return 0;
    }
    printf("samples %zu\n", n);
    printf("outputs %d\n", RPR3_NUM_OUTPUTS);
    printf("repeats %d\n", repeats);
    printf("floor_ns %.3f\n", 1e9 * best_floor / (double)n);
    printf("floor_gen_ns %.3f\n", 1e9 * best_floor_gen / (double)n);
    printf("floor_checksum %.17g\n", acc_floor);
    printf("floor_gen_checksum %.17g\n", acc_floor_gen);
    if (!floor_only) {
        printf("single_ns %.3f\n", 1e9 * best_single / (double)n);
        printf("batch_ns %.3f\n", 1e9 * best_batch / (double)n);
        printf("batch_small_ns %.3f\n", 1e9 * best_small / (double)((n / nsmall) * nsmall));
        printf("single_failed %zu\n", failed_single);
        printf("batch_failed %zu\n", failed_batch);
        printf("batch_small_failed %zu\n", failed_small);
        /* The same sum of one output in the same order: equal if single and batch agree. */
        printf("checksum_output %s\n", rpr3_output_names[column]);
        printf("single_checksum %.17g\n", acc_single);
        printf("batch_checksum %.17g\n", column_sum(out, n, column));
        printf("probe_index %zu\n", n / 2);
        for (k = 0; k < RPR3_NUM_OUTPUTS; ++k) {
            printf("probe %s %.17g\n", rpr3_output_names[k], out[(n / 2) * RPR3_NUM_OUTPUTS + k]);
        }
    }
    free(inputs);
    free(out);
    free(small_out);
    return 0;
}
