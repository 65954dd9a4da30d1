/* C timing harness of rpr3gen's generated control model (run by benchmarks/run.py, section
 * "Control model", through benchmarks/rpr3bench/charness.py). One build per variant (revolute
 * or prismatic: every variant defines the same names).
 *
 * Build (from the repository root), as the harness does (the runtime's flags, minus -fPIC
 * -shared; and once more with -O2):
 *   cc -std=c99 -O3 -fno-math-errno -fno-trapping-math -march=native -mno-fma -I generated/revolute \
 *      benchmarks/bench_control.c generated/revolute/rpr3.c -lm -o bench_control
 *
 * Usage:
 *   bench_control PARAMS INPUTS N SEGMENT REPEATS
 *     PARAMS   text file of "name value" lines (the output of `rpr3gen params`), any order
 *     INPUTS   raw native-endian float64: q (N x 3), then qd (N x 3), then qdd (N x 3): N / SEGMENT
 *              trajectories of SEGMENT samples each, one after the other, sampled every 1 ms
 *     N        number of samples in INPUTS (a multiple of SEGMENT)
 *     SEGMENT  samples per trajectory; the forward kinematics is tracked along each, from its
 *              first pose
 *     REPEATS  timed repeats of every loop (after one untimed warm-up); the median and the best
 *              are reported
 *
 * Before timing, and untimed, the harness computes from the true poses what a controller reads:
 * the actuator coordinates qa = rpr3_actuator_coordinates(q) (encoders), their rates
 * qa' = J(q) q' (rpr3_actuator_jacobian), and the efforts tau of rpr3_inverse_dynamics(q, q',
 * q'') (the m10_* or f21z_* outputs).
 *
 * Prints "key value" lines. Times are ns per call (per sample for the batches), of one pass over
 * the N samples, "_med" the median and "_best" the best of REPEATS passes; the passes of the
 * different loops are interleaved so that they share machine conditions.
 *
 *   floor_trig          sin and cos of phi, 3 sqrt (leg lengths) and one more sqrt, the libm calls
 *                       of the straight-line control functions (the 4th sqrt is their
 *                       conditioning guard's), with the multiply-adds that form the arguments
 *   floor_atan2         floor_trig plus the 3 atan2 of the leg angles: the libm calls of
 *                       rpr3_inverse_dynamics and of the revolute rpr3_actuator_coordinates
 *   single_NAME         rpr3_NAME once per sample (independent samples, back to back), into one
 *                       cache-resident buffer, for NAME = actuator_coordinates, actuator_jacobian,
 *                       jacobian_rate, task_space_dynamics, forward_dynamics, inverse_dynamics
 *   batch_NAME          rpr3_NAME_batch over the N samples (output N x size, about 2.5 MB at most)
 *   fk_predicted        rpr3_forward_kinematics along each trajectory, q_near = 2 q[k-1] - q[k-2]
 *                       of its own two previous results (the tracked case; q_near = q[0] at the
 *                       start), so each call waits for the previous one
 *   fk_previous         the same with q_near = q[k-1], its previous result
 *   tick                one control tick (below), tracked along each trajectory
 *   tick_id             the same tick with rpr3_inverse_dynamics in place of the task-space
 *                       dynamics and the torque solve
 *
 * The control tick (computed torque in task space, 1 kHz): from the encoders qa, qa' and the
 * desired q*, q*', q*'' (the trajectory itself):
 *   q    = rpr3_forward_kinematics(qa, q_near = 2 q[k-1] - q[k-2])
 *   J    = rpr3_actuator_jacobian(q); J^-1 by cofactors (one division)
 *   q'   = J^-1 qa'                                   (velocity solve)
 *   M, c = rpr3_task_space_dynamics(q, q')
 *   a    = q*'' + KD (q*' - q') + KP (q* - q)
 *   tau  = J^-T (M a + c)                             (computed torque solve)
 * tick_id replaces the last two steps by tau = the efforts of rpr3_inverse_dynamics(q, q', a).
 *
 * Checks (untimed): fk_err_xy / fk_err_phi, the largest distance of the tracked pose from the
 * true pose; tick_tau_err / tick_id_tau_err, the largest |tau_tick - tau_ID| over the largest
 * |tau_ID| (on the trajectory the PD terms vanish); fd_abs_err.S and fd_qdd_max.S, per
 * trajectory S, the largest |rpr3_forward_dynamics(q, q', tau_ID) - q''| and the largest |q''|;
 * mismatch_NAME, samples where single call and batch differ in a bit; failures of every call.
 * tick_p50/p99/max: the latency of single ticks, each timed by its own pair of clock_gettime
 * calls (clock_ns: the cost of one such pair, included).
 */
#define _POSIX_C_SOURCE 199309L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rpr3.h"

#define KP 900.0
#define KD 60.0
#define MAX_REPEATS 1001

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e9 * (double)ts.tv_sec + (double)ts.tv_nsec;
}

static int read_params(const char *path, double *params)
{
    char name[64];
    double value;
    int seen[RPR3_NUM_PARAMS] = {0};
    int k;
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        fprintf(stderr, "bench_control: cannot open %s\n", path);
        return 1;
    }
    while (fscanf(f, "%63s %lf", name, &value) == 2) {
        for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
            if (strcmp(rpr3_param_names[k], name) == 0) {
                params[k] = value;
                seen[k] = 1;
            }
        }
    }
    fclose(f);
    for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
        if (!seen[k]) {
            fprintf(stderr, "bench_control: parameter %s missing\n", rpr3_param_names[k]);
            return 1;
        }
    }
    return 0;
}

static int output_index(const char *name)
{
    int k;
    for (k = 0; k < RPR3_NUM_OUTPUTS; ++k) {
        if (strcmp(rpr3_output_names[k], name) == 0) {
            return k;
        }
    }
    return -1;
}

/* Everything a loop reads. */
typedef struct {
    const double *params;
    size_t n, segment;
    const double *q, *qd, *qdd;     /* the trajectory: true pose, velocity, acceleration */
    double *qa, *qa_dot, *tau;      /* encoders and the efforts of the inverse dynamics */
    int effort[3];                  /* output index of m10_* or f21z_* */
} Data;

/* ------------------------------------------------------------------------------------------ */
/* Floors: the libm calls of the generated functions, nothing else. */

static double floor_trig(const double *params, size_t n, const double *q)
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
        const double LA = sqrt(lxA * lxA + lyA * lyA), LB = sqrt(lxB * lxB + lyB * lyB);
        const double LC = sqrt(lxC * lxC + lyC * lyC);
        acc += LA + LB + LC + sqrt(LA * LB * LC);
    }
    return acc;
}

static double floor_atan2(const double *params, size_t n, const double *q)
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
        const double LA = sqrt(lxA * lxA + lyA * lyA), LB = sqrt(lxB * lxB + lyB * lyB);
        const double LC = sqrt(lxC * lxC + lyC * lyC);
        const double angles = atan2(lyA, lxA) + atan2(lyB, lxB) + atan2(lyC, lxC);
        acc += LA + LB + LC + sqrt(LA * LB * LC) + angles;
    }
    return acc;
}

/* ------------------------------------------------------------------------------------------ */
/* Single calls on independent samples, back to back, into one buffer. */

static double single_actuator_coordinates(const Data *d, size_t *failed)
{
    double out[3], acc = 0.0;
    size_t i;
    for (i = 0; i < d->n; ++i) {
        *failed += rpr3_actuator_coordinates(d->params, d->q + 3 * i, out) != RPR3_OK;
        acc += out[0];
    }
    return acc;
}

static double single_actuator_jacobian(const Data *d, size_t *failed)
{
    double out[9], acc = 0.0;
    size_t i;
    for (i = 0; i < d->n; ++i) {
        *failed += rpr3_actuator_jacobian(d->params, d->q + 3 * i, out) != RPR3_OK;
        acc += out[0];
    }
    return acc;
}

static double single_jacobian_rate(const Data *d, size_t *failed)
{
    double out[3], acc = 0.0;
    size_t i;
    for (i = 0; i < d->n; ++i) {
        *failed += rpr3_jacobian_rate(d->params, d->q + 3 * i, d->qd + 3 * i, out) != RPR3_OK;
        acc += out[0];
    }
    return acc;
}

static double single_task_space_dynamics(const Data *d, size_t *failed)
{
    double M[9], c[3], acc = 0.0;
    size_t i;
    for (i = 0; i < d->n; ++i) {
        *failed += rpr3_task_space_dynamics(d->params, d->q + 3 * i, d->qd + 3 * i, M, c)
                   != RPR3_OK;
        acc += M[0] + c[0];
    }
    return acc;
}

static double single_forward_dynamics(const Data *d, size_t *failed)
{
    double out[3], acc = 0.0;
    size_t i;
    for (i = 0; i < d->n; ++i) {
        *failed += rpr3_forward_dynamics(d->params, d->q + 3 * i, d->qd + 3 * i, d->tau + 3 * i,
                                         out) != RPR3_OK;
        acc += out[0];
    }
    return acc;
}

static double single_inverse_dynamics(const Data *d, size_t *failed)
{
    double out[RPR3_NUM_OUTPUTS], acc = 0.0;
    size_t i;
    for (i = 0; i < d->n; ++i) {
        *failed += rpr3_inverse_dynamics(d->params, d->q + 3 * i, d->qd + 3 * i, d->qdd + 3 * i,
                                          out) != RPR3_OK;
        acc += out[d->effort[0]];
    }
    return acc;
}

/* ------------------------------------------------------------------------------------------ */
/* Batches over the N samples. */

typedef struct {
    double *qa, *J, *Jdqd, *M, *c, *qdd, *out;
} Batch;

static size_t batch_actuator_coordinates(const Data *d, Batch *b)
{
    return rpr3_actuator_coordinates_batch(d->params, d->n, d->q, b->qa);
}

static size_t batch_actuator_jacobian(const Data *d, Batch *b)
{
    return rpr3_actuator_jacobian_batch(d->params, d->n, d->q, b->J);
}

static size_t batch_jacobian_rate(const Data *d, Batch *b)
{
    return rpr3_jacobian_rate_batch(d->params, d->n, d->q, d->qd, b->Jdqd);
}

static size_t batch_task_space_dynamics(const Data *d, Batch *b)
{
    return rpr3_task_space_dynamics_batch(d->params, d->n, d->q, d->qd, b->M, b->c);
}

static size_t batch_forward_dynamics(const Data *d, Batch *b)
{
    return rpr3_forward_dynamics_batch(d->params, d->n, d->q, d->qd, d->tau, b->qdd);
}

static size_t batch_inverse_dynamics(const Data *d, Batch *b)
{
    return rpr3_inverse_dynamics_batch(d->params, d->n, d->q, d->qd, d->qdd, b->out);
}

/* ------------------------------------------------------------------------------------------ */
/* Tracked forward kinematics and the control tick. */

/* q_near for sample k of a segment: its first true pose at k = 0, else from the results so far
 * (seg: the segment's results, k x 3): 2 q[k-1] - q[k-2] (predicted, from k = 2) or q[k-1]. */
static void reference(const double *start, const double *seg, size_t k, int predicted,
                      double *near)
{
    int j;
    for (j = 0; j < 3; ++j) {
        if (k == 0) {
            near[j] = start[j];
        } else if (predicted && k > 1) {
            near[j] = 2.0 * seg[3 * (k - 1) + j] - seg[3 * (k - 2) + j];
        } else {
            near[j] = seg[3 * (k - 1) + j];
        }
    }
}

/* Tracked FK along every segment; poses into q_out (N x 3). Returns the failures. */
static size_t fk_track(const Data *d, int predicted, double *q_out)
{
    double near[3];
    size_t failed = 0, s, k;
    for (s = 0; s < d->n; s += d->segment) {
        for (k = 0; k < d->segment; ++k) {
            const size_t i = s + k;
            double *q = q_out + 3 * i;
            reference(d->q + 3 * s, q_out + 3 * s, k, predicted, near);
            if (rpr3_forward_kinematics(d->params, d->qa + 3 * i, near, q) != RPR3_OK) {
                memcpy(q, near, sizeof near);
                ++failed;
            }
        }
    }
    return failed;
}

/* J^-1 = adj(J) / det J: cof holds the cofactors C[i][j] row-major; returns det J. */
static double cofactors(const double *J, double *cof)
{
    cof[0] = J[4] * J[8] - J[5] * J[7];
    cof[1] = J[5] * J[6] - J[3] * J[8];
    cof[2] = J[3] * J[7] - J[4] * J[6];
    cof[3] = J[2] * J[7] - J[1] * J[8];
    cof[4] = J[0] * J[8] - J[2] * J[6];
    cof[5] = J[1] * J[6] - J[0] * J[7];
    cof[6] = J[1] * J[5] - J[2] * J[4];
    cof[7] = J[2] * J[3] - J[0] * J[5];
    cof[8] = J[0] * J[4] - J[1] * J[3];
    return J[0] * cof[0] + J[1] * cof[1] + J[2] * cof[2];
}

/* One control tick of sample i (see the header comment); q, tau: its results. Returns 0 or
 * the step that failed. */
static int tick(const Data *d, size_t i, const double *near, double *q, double *tau)
{
    const double *q_des = d->q + 3 * i, *qd_des = d->qd + 3 * i, *qdd_des = d->qdd + 3 * i;
    const double *w = d->qa_dot + 3 * i;
    double J[9], cof[9], M[9], c[3], qd[3], a[3], r[3], det, inv;
    int j;
    if (rpr3_forward_kinematics(d->params, d->qa + 3 * i, near, q) != RPR3_OK) {
        return 1;
    }
    if (rpr3_actuator_jacobian(d->params, q, J) != RPR3_OK) {
        return 2;
    }
    det = cofactors(J, cof);
    if (!(fabs(det) > 0.0)) {
        return 3;
    }
    inv = 1.0 / det;
    for (j = 0; j < 3; ++j) { /* q' = J^-1 qa' = adj(J) qa' / det, adj = cof^T */
        qd[j] = (cof[j] * w[0] + cof[3 + j] * w[1] + cof[6 + j] * w[2]) * inv;
    }
    if (rpr3_task_space_dynamics(d->params, q, qd, M, c) != RPR3_OK) {
        return 4;
    }
    for (j = 0; j < 3; ++j) {
        a[j] = qdd_des[j] + KD * (qd_des[j] - qd[j]) + KP * (q_des[j] - q[j]);
    }
    for (j = 0; j < 3; ++j) {
        r[j] = M[3 * j] * a[0] + M[3 * j + 1] * a[1] + M[3 * j + 2] * a[2] + c[j];
    }
    for (j = 0; j < 3; ++j) { /* tau = J^-T r = cof r / det */
        tau[j] = (cof[3 * j] * r[0] + cof[3 * j + 1] * r[1] + cof[3 * j + 2] * r[2]) * inv;
    }
    return 0;
}

/* The same tick with the inverse dynamics for the efforts. */
static int tick_id(const Data *d, size_t i, const double *near, double *q, double *tau)
{
    const double *q_des = d->q + 3 * i, *qd_des = d->qd + 3 * i, *qdd_des = d->qdd + 3 * i;
    const double *w = d->qa_dot + 3 * i;
    double J[9], cof[9], out[RPR3_NUM_OUTPUTS], qd[3], a[3], det, inv;
    int j;
    if (rpr3_forward_kinematics(d->params, d->qa + 3 * i, near, q) != RPR3_OK) {
        return 1;
    }
    if (rpr3_actuator_jacobian(d->params, q, J) != RPR3_OK) {
        return 2;
    }
    det = cofactors(J, cof);
    if (!(fabs(det) > 0.0)) {
        return 3;
    }
    inv = 1.0 / det;
    for (j = 0; j < 3; ++j) {
        qd[j] = (cof[j] * w[0] + cof[3 + j] * w[1] + cof[6 + j] * w[2]) * inv;
    }
    for (j = 0; j < 3; ++j) {
        a[j] = qdd_des[j] + KD * (qd_des[j] - qd[j]) + KP * (q_des[j] - q[j]);
    }
    if (rpr3_inverse_dynamics(d->params, q, qd, a, out) != RPR3_OK) {
        return 4;
    }
    for (j = 0; j < 3; ++j) {
        tau[j] = out[d->effort[j]];
    }
    return 0;
}

typedef int (*TickFn)(const Data *, size_t, const double *, double *, double *);

/* Ticks along every segment; poses into q_out, efforts into tau_out (N x 3). With lat, each
 * tick is timed on its own (ns) into lat. Returns the failures. */
static size_t run_ticks(const Data *d, TickFn fn, double *q_out, double *tau_out, double *lat)
{
    double near[3], t0 = 0.0;
    size_t failed = 0, s, k;
    for (s = 0; s < d->n; s += d->segment) {
        for (k = 0; k < d->segment; ++k) {
            const size_t i = s + k;
            double *q = q_out + 3 * i;
            reference(d->q + 3 * s, q_out + 3 * s, k, 1, near);
            if (lat) {
                t0 = now_ns();
            }
            if (fn(d, i, near, q, tau_out + 3 * i) != 0) {
                memcpy(q, near, sizeof near);
                ++failed;
            }
            if (lat) {
                lat[i] = now_ns() - t0;
            }
        }
    }
    return failed;
}

/* ------------------------------------------------------------------------------------------ */

static int compare(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

enum {
    T_FLOOR_TRIG, T_FLOOR_ATAN2,
    T_S_AC, T_S_J, T_S_JR, T_S_TSD, T_S_FD, T_S_ID,
    T_B_AC, T_B_J, T_B_JR, T_B_TSD, T_B_FD, T_B_ID,
    T_FK_PRED, T_FK_PREV, T_TICK, T_TICK_ID, T_COUNT
};
static const char *const T_NAMES[T_COUNT] = {
    "floor_trig", "floor_atan2",
    "single_actuator_coordinates", "single_actuator_jacobian", "single_jacobian_rate",
    "single_task_space_dynamics", "single_forward_dynamics", "single_inverse_dynamics",
    "batch_actuator_coordinates", "batch_actuator_jacobian", "batch_jacobian_rate",
    "batch_task_space_dynamics", "batch_forward_dynamics", "batch_inverse_dynamics",
    "fk_predicted", "fk_previous", "tick", "tick_id",
};

static size_t mismatches(const double *a, const double *b, size_t n, size_t size)
{
    size_t i, count = 0;
    for (i = 0; i < n; ++i) {
        count += memcmp(a + i * size, b + i * size, size * sizeof *a) != 0;
    }
    return count;
}

/* Largest |a - b| over the largest |b|, over n x 3 values. */
static double relative_error(const double *a, const double *b, size_t n)
{
    double err = 0.0, scale = 0.0;
    size_t k;
    for (k = 0; k < 3 * n; ++k) {
        err = fmax(err, fabs(a[k] - b[k]));
        scale = fmax(scale, fabs(b[k]));
    }
    return err / scale;
}

int main(int argc, char **argv)
{
    static double times[T_COUNT][MAX_REPEATS];
    double params[RPR3_NUM_PARAMS], out[RPR3_NUM_OUTPUTS], J[9];
    double *inputs, *scratch, *q_fk, *tau_tick, *lat, *single_store;
    double sink = 0.0, t0, clock_ns;
    size_t n, segment, i, s, failed[T_COUNT] = {0}, nfail;
    int repeats, r, t, j;
    const char *family = strcmp(RPR3_ACTUATION, "revolute") == 0 ? "m10" : "f21z";
    Data d;
    Batch b;
    FILE *f;

    if (argc != 6) {
        fprintf(stderr, "usage: %s PARAMS INPUTS N SEGMENT REPEATS\n", argv[0]);
        return 2;
    }
    n = (size_t)strtoull(argv[3], NULL, 10);
    segment = (size_t)strtoull(argv[4], NULL, 10);
    repeats = atoi(argv[5]);
    if (n == 0 || segment < 3 || n % segment != 0 || repeats < 1 || repeats > MAX_REPEATS
        || read_params(argv[1], params) != 0) {
        fprintf(stderr, "bench_control: bad arguments\n");
        return 2;
    }
    inputs = malloc(15 * n * sizeof(double));
    f = fopen(argv[2], "rb");
    if (inputs == NULL || f == NULL || fread(inputs, sizeof(double), 9 * n, f) != 9 * n) {
        fprintf(stderr, "bench_control: cannot read %zu samples from %s\n", n, argv[2]);
        return 2;
    }
    fclose(f);
    d.params = params;
    d.n = n;
    d.segment = segment;
    d.q = inputs;
    d.qd = inputs + 3 * n;
    d.qdd = inputs + 6 * n;
    d.qa = inputs + 9 * n;
    d.qa_dot = inputs + 12 * n;
    d.tau = malloc(3 * n * sizeof(double));
    for (j = 0; j < 3; ++j) {
        char name[16];
        sprintf(name, "%s_%c", family, "ABC"[j]);
        d.effort[j] = output_index(name);
        if (d.effort[j] < 0) {
            fprintf(stderr, "bench_control: no output %s\n", name);
            return 2;
        }
    }
    /* What the controller reads, from the true poses (untimed). */
    nfail = 0;
    for (i = 0; i < n; ++i) {
        nfail += rpr3_actuator_coordinates(params, d.q + 3 * i, d.qa + 3 * i) != RPR3_OK;
        nfail += rpr3_actuator_jacobian(params, d.q + 3 * i, J) != RPR3_OK;
        for (j = 0; j < 3; ++j) {
            const double *v = d.qd + 3 * i;
            d.qa_dot[3 * i + j] = J[3 * j] * v[0] + J[3 * j + 1] * v[1] + J[3 * j + 2] * v[2];
        }
        nfail += rpr3_inverse_dynamics(params, d.q + 3 * i, d.qd + 3 * i, d.qdd + 3 * i, out)
                 != RPR3_OK;
        for (j = 0; j < 3; ++j) {
            d.tau[3 * i + j] = out[d.effort[j]];
        }
    }
    if (nfail) {
        fprintf(stderr, "bench_control: %zu failed calls preparing the inputs\n", nfail);
        return 1;
    }
    b.qa = malloc(3 * n * sizeof(double));
    b.J = malloc(9 * n * sizeof(double));
    b.Jdqd = malloc(3 * n * sizeof(double));
    b.M = malloc(9 * n * sizeof(double));
    b.c = malloc(3 * n * sizeof(double));
    b.qdd = malloc(3 * n * sizeof(double));
    b.out = malloc(RPR3_NUM_OUTPUTS * n * sizeof(double));
    q_fk = malloc(3 * n * sizeof(double));
    tau_tick = malloc(3 * n * sizeof(double));
    lat = malloc(n * sizeof(double));
    scratch = malloc(3 * n * sizeof(double));
    single_store = malloc(RPR3_NUM_OUTPUTS * n * sizeof(double));
    if (!d.tau || !b.qa || !b.J || !b.Jdqd || !b.M || !b.c || !b.qdd || !b.out || !q_fk
        || !tau_tick || !lat || !scratch || !single_store) {
        fprintf(stderr, "bench_control: out of memory\n");
        return 2;
    }
    memset(b.out, 0, RPR3_NUM_OUTPUTS * n * sizeof(double)); /* touch the pages */

    for (r = -1; r < repeats; ++r) { /* r = -1: warm-up, not kept */
        double el[T_COUNT];
        memset(failed, 0, sizeof failed);
#define TIME(T, EXPR)                                                                          \
    do {                                                                                       \
        t0 = now_ns();                                                                         \
        EXPR;                                                                                  \
        el[T] = (now_ns() - t0) / (double)n;                                                   \
    } while (0)
        TIME(T_FLOOR_TRIG, sink += floor_trig(params, n, d.q));
        TIME(T_FLOOR_ATAN2, sink += floor_atan2(params, n, d.q));
        TIME(T_S_AC, sink += single_actuator_coordinates(&d, &failed[T_S_AC]));
        TIME(T_S_J, sink += single_actuator_jacobian(&d, &failed[T_S_J]));
        TIME(T_S_JR, sink += single_jacobian_rate(&d, &failed[T_S_JR]));
        TIME(T_S_TSD, sink += single_task_space_dynamics(&d, &failed[T_S_TSD]));
        TIME(T_S_FD, sink += single_forward_dynamics(&d, &failed[T_S_FD]));
        TIME(T_S_ID, sink += single_inverse_dynamics(&d, &failed[T_S_ID]));
        TIME(T_B_AC, failed[T_B_AC] = batch_actuator_coordinates(&d, &b));
        TIME(T_B_J, failed[T_B_J] = batch_actuator_jacobian(&d, &b));
        TIME(T_B_JR, failed[T_B_JR] = batch_jacobian_rate(&d, &b));
        TIME(T_B_TSD, failed[T_B_TSD] = batch_task_space_dynamics(&d, &b));
        TIME(T_B_FD, failed[T_B_FD] = batch_forward_dynamics(&d, &b));
        TIME(T_B_ID, failed[T_B_ID] = batch_inverse_dynamics(&d, &b));
        TIME(T_FK_PRED, failed[T_FK_PRED] = fk_track(&d, 1, q_fk));
        TIME(T_FK_PREV, failed[T_FK_PREV] = fk_track(&d, 0, scratch));
        TIME(T_TICK_ID, failed[T_TICK_ID] = run_ticks(&d, tick_id, scratch, single_store, NULL));
        TIME(T_TICK, failed[T_TICK] = run_ticks(&d, tick, scratch, tau_tick, NULL));
#undef TIME
        if (r >= 0) {
            for (t = 0; t < T_COUNT; ++t) {
                times[t][r] = el[t];
            }
        }
    }

    printf("variant %s\n", RPR3_VARIANT);
    printf("samples %zu\n", n);
    printf("segment %zu\n", segment);
    printf("repeats %d\n", repeats);
    for (t = 0; t < T_COUNT; ++t) {
        double best = times[t][0];
        for (r = 1; r < repeats; ++r) {
            best = fmin(best, times[t][r]);
        }
        printf("%s_best %.3f\n", T_NAMES[t], best);
        printf("%s_med %.3f\n", T_NAMES[t], median(times[t], repeats));
        printf("%s_failed %zu\n", T_NAMES[t], failed[t]);
    }

    /* Checks (untimed). */
    {
        double err_xy = 0.0, err_phi = 0.0;
        for (i = 0; i < n; ++i) {
            err_xy = fmax(err_xy, hypot(q_fk[3 * i] - d.q[3 * i], q_fk[3 * i + 1] - d.q[3 * i + 1]));
            err_phi = fmax(err_phi, fabs(q_fk[3 * i + 2] - d.q[3 * i + 2]));
        }
        printf("fk_err_xy %.3e\n", err_xy);
        printf("fk_err_phi %.3e\n", err_phi);
    }
    printf("tick_tau_err %.3e\n", relative_error(tau_tick, d.tau, n));
    printf("tick_id_tau_err %.3e\n", relative_error(single_store, d.tau, n));
    for (s = 0; s < n / segment; ++s) { /* forward dynamics of the ID efforts, per trajectory */
        double err = 0.0, scale = 0.0, qdd[3];
        size_t bad = 0;
        for (i = s * segment; i < (s + 1) * segment; ++i) {
            bad += rpr3_forward_dynamics(params, d.q + 3 * i, d.qd + 3 * i, d.tau + 3 * i, qdd)
                   != RPR3_OK;
            for (j = 0; j < 3; ++j) {
                err = fmax(err, fabs(qdd[j] - d.qdd[3 * i + j]));
                scale = fmax(scale, fabs(d.qdd[3 * i + j]));
            }
        }
        printf("fd_abs_err.%zu %.3e\n", s, err);
        printf("fd_qdd_max.%zu %.6e\n", s, scale);
        printf("fd_failed.%zu %zu\n", s, bad);
    }
    /* Single call against batch, bit for bit. */
    for (i = 0; i < n; ++i) {
        rpr3_actuator_coordinates(params, d.q + 3 * i, single_store + 3 * i);
    }
    printf("mismatch_actuator_coordinates %zu\n", mismatches(single_store, b.qa, n, 3));
    for (i = 0; i < n; ++i) {
        rpr3_actuator_jacobian(params, d.q + 3 * i, single_store + 9 * i);
    }
    printf("mismatch_actuator_jacobian %zu\n", mismatches(single_store, b.J, n, 9));
    for (i = 0; i < n; ++i) {
        rpr3_jacobian_rate(params, d.q + 3 * i, d.qd + 3 * i, single_store + 3 * i);
    }
    printf("mismatch_jacobian_rate %zu\n", mismatches(single_store, b.Jdqd, n, 3));
    for (i = 0; i < n; ++i) {
        rpr3_task_space_dynamics(params, d.q + 3 * i, d.qd + 3 * i, single_store + 12 * i,
                                 single_store + 12 * i + 9);
    }
    nfail = 0;
    for (i = 0; i < n; ++i) {
        nfail += memcmp(single_store + 12 * i, b.M + 9 * i, 9 * sizeof(double)) != 0
                 || memcmp(single_store + 12 * i + 9, b.c + 3 * i, 3 * sizeof(double)) != 0;
    }
    printf("mismatch_task_space_dynamics %zu\n", nfail);
    for (i = 0; i < n; ++i) {
        rpr3_forward_dynamics(params, d.q + 3 * i, d.qd + 3 * i, d.tau + 3 * i,
                              single_store + 3 * i);
    }
    printf("mismatch_forward_dynamics %zu\n", mismatches(single_store, b.qdd, n, 3));
    for (i = 0; i < n; ++i) {
        rpr3_inverse_dynamics(params, d.q + 3 * i, d.qd + 3 * i, d.qdd + 3 * i,
                              single_store + RPR3_NUM_OUTPUTS * i);
    }
    printf("mismatch_inverse_dynamics %zu\n",
           mismatches(single_store, b.out, n, RPR3_NUM_OUTPUTS));

    /* Latency of single ticks, each timed on its own. */
    {
        double pairs[1001];
        for (j = 0; j < 1001; ++j) {
            t0 = now_ns();
            pairs[j] = now_ns() - t0;
        }
        clock_ns = median(pairs, 1001);
        for (r = 0; r < 3; ++r) { /* keep the last of three passes (warm) */
            run_ticks(&d, tick, scratch, tau_tick, lat);
        }
        qsort(lat, n, sizeof *lat, compare);
        printf("clock_ns %.1f\n", clock_ns);
        printf("tick_p50 %.1f\n", lat[n / 2]);
        printf("tick_p99 %.1f\n", lat[(size_t)(0.99 * (double)(n - 1))]);
        printf("tick_max %.1f\n", lat[n - 1]);
    }
    printf("sink %.17g\n", sink);
    free(inputs);
    free(d.tau);
    free(b.qa);
    free(b.J);
    free(b.Jdqd);
    free(b.M);
    free(b.c);
    free(b.qdd);
    free(b.out);
    free(q_fk);
    free(tau_tick);
    free(lat);
    free(scratch);
    free(single_store);
    return 0;
}
