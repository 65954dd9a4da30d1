/* 1 kHz task-space computed-torque tracking of the paper's trajectories, closed on encoders.
 *
 * Plant: the robot with masses and inertias a few percent off the model, its platform state
 * (q, qd) integrated by RK4 of the generated rpr3_forward_dynamics, four substeps per tick,
 * under the efforts held over the tick. Sensors: the actuator coordinates of the plant
 * (rpr3_actuator_coordinates) rounded to whole encoder counts: 2^17 counts per revolution
 * (revolute actuation) or 1 um per count (prismatic). Controller, nominal model, every tick:
 *   qa    = counts * resolution;  qa' = (counts - previous counts) * resolution / dt, low-pass
 *   q_d, qd_d, qdd_d = the reference at t (eq. 3), first: it needs no measurement
 *   q, J  = rpr3_forward_kinematics_jacobian(qa, q_near = 2 q[k-1] - q[k-2])
 *           (tracked; J = d qa / d q at q, which the tracked Newton evaluated there)
 *   q'    : J q' = qa'
 *   M, c  = rpr3_task_space_dynamics(q, q')
 *   tau   : J^T tau = M (qdd_d + Kd (qd_d - q') + Kp (q_d - q)) + c
 *           (both solves from J's cofactors and 1 / det J, computed once a tick)
 * Prints the tracking error, the pose and velocity estimates' errors, the failed calls and the
 * latency (p50, p99, max) of the forward kinematics (with the rate filter and the reference
 * before it), of the rest of the tick (velocity, dynamics, law) and of the whole tick. The
 * ticks alternate between the two measures: an even tick is split at the end of its forward
 * kinematics (a clock read between the parts), an odd tick is timed whole, with no clock read
 * inside it (a read costs ~30 ns, which the whole tick would otherwise carry). The variant
 * (actuation) is the generated folder the program is built with. The arguments are
 * control_loop.py's (but --model and --actuation):
 *
 *   make && ./control_loop_revolute [--params FILE] [--trajectory rectilinear|rotation]
 *                                   [--seconds T] [--offset MM] [rectilinear|rotation]
 *
 * --params FILE (default paper.params): "name value" lines, e.g. `rpr3gen params > paper.params`.
 */
#define _POSIX_C_SOURCE 199309L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rpr3.h"

#define PI 3.14159265358979323846
#define RATE_HZ 1000          /* controller ticks per second */
#define SUBSTEPS 4            /* RK4 steps of the plant per tick (4 kHz) */
#define KP 900.0              /* s^-2 */
#define KD 60.0               /* s^-1: critically damped at 30 rad/s */
#define RATE_CUTOFF_HZ 100.0  /* first-order low-pass on the differenced counts */
#define TRANSIENT 0.05        /* s, left out of the "after" tracking error */
#define COUNTS_PER_REV 131072 /* 2^17, revolute actuation */
#define METRES_PER_COUNT 1e-6 /* prismatic actuation */
#define DURATION 3.0          /* s, the paper's motions (eq. 3) */

static int index_of(const char *const *names, int count, const char *name)
{
    int k;
    for (k = 0; k < count; ++k) {
        if (strcmp(names[k], name) == 0) {
            return k;
        }
    }
    return -1;
}

static int read_params(const char *path, double *params)
{
    char name[64];
    double value;
    int seen = 0;
    int k;
    FILE *file = fopen(path, "r");
    if (file == NULL) {
        fprintf(stderr, "control_loop: cannot open %s\n", path);
        return -1;
    }
    for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
        params[k] = NAN;
    }
    while (fscanf(file, "%63s %lf", name, &value) == 2) {
        k = index_of(rpr3_param_names, RPR3_NUM_PARAMS, name);
        if (k < 0) {
            fprintf(stderr, "control_loop: %s: unknown parameter %s\n", path, name);
            fclose(file);
            return -1;
        }
        params[k] = value;
        ++seen;
    }
    fclose(file);
    for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
        if (!isfinite(params[k])) {
            fprintf(stderr, "control_loop: %s: missing %s\n", path, rpr3_param_names[k]);
            return -1;
        }
    }
    return seen;
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e9 + ts.tv_nsec;
}

/* Paper eq. (3), q = q* (1 - cos(pi t / T)), and its first two derivatives. */
static void reference(const double *amplitude, double t, double *q, double *qd, double *qdd)
{
    const double w = PI / DURATION, c = cos(w * t), s = sin(w * t);
    int k;
    for (k = 0; k < 3; ++k) {
        q[k] = amplitude[k] * (1.0 - c);
        qd[k] = amplitude[k] * (w * s);
        qdd[k] = amplitude[k] * (w * w * c);
    }
}

/* A 3x3 row-major matrix A's cofactors c (A^-1 = c^T / det A) and 1 / det A, computed once for
 * the tick's two solves (J q' = qa' and J^T tau = f). Returns -1 when A is singular to round-off:
 * |det A| at most 1e-12 times the product of its row norms (compared squared: no sqrt). */
struct cofactors {
    double c[9], inv;
};

static int cofactors3(const double *a, struct cofactors *f)
{
    double *c = f->c, det;
    c[0] = a[4] * a[8] - a[5] * a[7], c[1] = a[5] * a[6] - a[3] * a[8];
    c[2] = a[3] * a[7] - a[4] * a[6], c[3] = a[7] * a[2] - a[8] * a[1];
    c[4] = a[8] * a[0] - a[6] * a[2], c[5] = a[6] * a[1] - a[7] * a[0];
    c[6] = a[1] * a[5] - a[2] * a[4], c[7] = a[2] * a[3] - a[0] * a[5];
    c[8] = a[0] * a[4] - a[1] * a[3];
    det = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
    if (!(det * det > 1e-24 * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
                          * (a[3] * a[3] + a[4] * a[4] + a[5] * a[5])
                          * (a[6] * a[6] + a[7] * a[7] + a[8] * a[8]))) {
        return -1;
    }
    f->inv = 1.0 / det;
    return 0;
}

/* Solves A x = b (transpose = 0) or A^T x = b (transpose = 1) from A's cofactors3. */
static void solve3(const struct cofactors *f, const double *b, int transpose, double *x)
{
    const double *c = f->c;
    double y0, y1, y2;
    if (transpose) { /* A^-T = C / det */
        y0 = c[0] * b[0] + c[1] * b[1] + c[2] * b[2];
        y1 = c[3] * b[0] + c[4] * b[1] + c[5] * b[2];
        y2 = c[6] * b[0] + c[7] * b[1] + c[8] * b[2];
    } else { /* A^-1 = C^T / det */
        y0 = c[0] * b[0] + c[3] * b[1] + c[6] * b[2];
        y1 = c[1] * b[0] + c[4] * b[1] + c[7] * b[2];
        y2 = c[2] * b[0] + c[5] * b[1] + c[8] * b[2];
    }
    x[0] = y0 * f->inv, x[1] = y1 * f->inv, x[2] = y2 * f->inv;
}

/* Plant: one tick of RK4 of the true forward dynamics under the efforts tau, in substeps. */
static int plant_step(const double *truth, double *q, double *qd, const double *tau, double dt)
{
    const double h = dt / SUBSTEPS;
    int s, k;
    for (s = 0; s < SUBSTEPS; ++s) {
        double a1[3], a2[3], a3[3], a4[3], q2[3], v2[3], q3[3], v3[3], q4[3], v4[3];
        if (rpr3_forward_dynamics(truth, q, qd, tau, a1) != RPR3_OK) {
            return -1;
        }
        for (k = 0; k < 3; ++k) {
            q2[k] = q[k] + 0.5 * h * qd[k];
            v2[k] = qd[k] + 0.5 * h * a1[k];
        }
        if (rpr3_forward_dynamics(truth, q2, v2, tau, a2) != RPR3_OK) {
            return -1;
        }
        for (k = 0; k < 3; ++k) {
            q3[k] = q[k] + 0.5 * h * v2[k];
            v3[k] = qd[k] + 0.5 * h * a2[k];
        }
        if (rpr3_forward_dynamics(truth, q3, v3, tau, a3) != RPR3_OK) {
            return -1;
        }
        for (k = 0; k < 3; ++k) {
            q4[k] = q[k] + h * v3[k];
            v4[k] = qd[k] + h * a3[k];
        }
        if (rpr3_forward_dynamics(truth, q4, v4, tau, a4) != RPR3_OK) {
            return -1;
        }
        for (k = 0; k < 3; ++k) {
            q[k] += h / 6.0 * (qd[k] + 2.0 * v2[k] + 2.0 * v3[k] + v4[k]);
            qd[k] += h / 6.0 * (a1[k] + 2.0 * a2[k] + 2.0 * a3[k] + a4[k]);
        }
    }
    return 0;
}

/* Sensors: the plant's actuator coordinates rounded to whole counts. */
static int encoders(const double *truth, const double *q, double resolution, long *counts)
{
    double qa[3];
    int k;
    if (rpr3_actuator_coordinates(truth, q, qa) != RPR3_OK) {
        return -1;
    }
    for (k = 0; k < 3; ++k) {
        counts[k] = lround(qa[k] / resolution);
    }
    return 0;
}

struct controller {
    const double *params; /* the nominal model */
    double amplitude[3];  /* of the trajectory, eq. (3) */
    double resolution;    /* rad or m per count */
    double alpha;         /* of the rate filter */
    double q1[3], q2[3];  /* the last two pose estimates (home before the first) */
    long counts[3];       /* the previous reading */
    int started;
    double rate[3];       /* filtered actuator rates */
    double qd[3];         /* velocity estimate */
    double tau[3];        /* the efforts commanded */
    long failed_fk, failed_jacobian, failed_dynamics;
};

/* The end of a tick begun at start: its latencies (controller_tick). */
static void finish(double start, double fk_end, int split, double *ns)
{
    const double end = now_ns();
    if (split) {
        ns[0] = fk_end - start;
        ns[1] = end - fk_end;
    } else {
        ns[2] = end - start;
    }
}

/* One tick: encoder counts at time t in, ctl->tau out. With split, ns[0] and ns[1] receive the
 * latencies of its forward kinematics and of the rest (three clock reads, one between them);
 * else ns[2] that of the whole tick (two clock reads, none inside it). */
static void controller_tick(struct controller *ctl, const long *counts, double t, int split,
                            double *ns)
{
    const double dt = 1.0 / RATE_HZ;
    const double start = now_ns();
    double qa[3], near[3], q[3], J[9], M[9], c[3], f[3], q_d[3], qd_d[3], qdd_d[3], acc[3];
    struct cofactors Jc;
    double fk_end = 0.0;
    const int first = !ctl->started;
    int status, i, k;

    for (k = 0; k < 3; ++k) { /* actuator positions and rates from the counts */
        qa[k] = counts[k] * ctl->resolution;
        if (!first) {
            const double raw = (counts[k] - ctl->counts[k]) * (ctl->resolution / dt);
            ctl->rate[k] += ctl->alpha * (raw - ctl->rate[k]);
        }
        ctl->counts[k] = counts[k];
        near[k] = 2.0 * ctl->q1[k] - ctl->q2[k];
    }
    ctl->started = 1;
    /* the reference (eq. 3: a cos and a sin of t) depends on no measurement: computed before the
     * forward kinematics, it runs beside that call's chain of dependent operations instead of
     * after it (the whole tick's p50 ~100 ns lower in most runs with revolute actuation on an
     * AMD EPYC; docs/performance-log.md, fourteenth stop) */
    reference(ctl->amplitude, t, q_d, qd_d, qdd_d);

    /* the pose and J there: tracked forward kinematics from the prediction */
    status = rpr3_forward_kinematics_jacobian(ctl->params, qa, near, q, J);
    if (split) {
        fk_end = now_ns();
    }
    if (status != RPR3_OK) {
        ++ctl->failed_fk;
        memcpy(q, near, sizeof q); /* coast on the prediction, with its J */
        status = rpr3_actuator_jacobian(ctl->params, q, J);
    }
    memcpy(ctl->q2, first ? q : ctl->q1, sizeof q); /* at first, at rest */
    memcpy(ctl->q1, q, sizeof q);

    if (status != RPR3_OK || cofactors3(J, &Jc) != 0) {
        ++ctl->failed_jacobian;
        finish(start, fk_end, split, ns);
        return; /* hold the last efforts */
    }
    solve3(&Jc, ctl->rate, 0, ctl->qd); /* the velocity: J q' = qa' */

    for (k = 0; k < 3; ++k) {
        acc[k] = qdd_d[k] + KD * (qd_d[k] - ctl->qd[k]) + KP * (q_d[k] - q[k]);
    }
    /* computed torque in task space: J^T tau = M acc + c */
    status = rpr3_task_space_dynamics(ctl->params, q, ctl->qd, M, c);
    if (status == RPR3_OK) {
        for (i = 0; i < 3; ++i) {
            f[i] = c[i];
            for (k = 0; k < 3; ++k) {
                f[i] += M[3 * i + k] * acc[k];
            }
        }
        solve3(&Jc, f, 1, ctl->tau);
    }
    if (status != RPR3_OK) {
        ++ctl->failed_dynamics;
    }
    finish(start, fk_end, split, ns);
}

/* control_loop.py's arguments: --params FILE, --trajectory NAME (or NAME alone), --seconds T,
 * --offset MM, each as "--name value" or "--name=value". Returns 0, or -1 on a bad argument. */
static int parse_arguments(int argc, char **argv, const char **params, const char **trajectory,
                           double *seconds, double *offset)
{
    const char *options[] = {"--params", "--trajectory", "--seconds", "--offset"};
    int a, k, positional = 0;
    for (a = 1; a < argc; ++a) {
        const char *value = NULL;
        char *end;
        if (strncmp(argv[a], "--", 2) != 0) { /* the trajectory, positional */
            if (positional++) {
                return -1;
            }
            *trajectory = argv[a];
            continue;
        }
        for (k = 0; k < 4; ++k) {
            const size_t n = strlen(options[k]);
            if (strncmp(argv[a], options[k], n) == 0 && argv[a][n] == '=') {
                value = argv[a] + n + 1;
                break;
            }
            if (strcmp(argv[a], options[k]) == 0 && a + 1 < argc) {
                value = argv[++a];
                break;
            }
        }
        if (value == NULL) {
            return -1;
        }
        if (k == 0) {
            *params = value;
        } else if (k == 1) {
            *trajectory = value;
        } else {
            const double number = strtod(value, &end);
            if (*end != '\0' || end == value) {
                return -1;
            }
            *(k == 2 ? seconds : offset) = number;
        }
    }
    return 0;
}

static int compare(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void print_latency(const char *label, double *ns, long n)
{
    if (n == 0) {
        printf("latency %s: no tick measured\n", label);
        return;
    }
    qsort(ns, (size_t)n, sizeof *ns, compare);
    printf("latency %s: p50 %.0f ns, p99 %.0f ns, max %.0f ns\n", label, ns[n / 2],
           ns[(long)(0.99 * (n - 1))], ns[n - 1]);
}

struct stats {
    double sum[2], max[2]; /* position (m), angle (rad) */
    long n;
};

static void add(struct stats *s, double position, double angle)
{
    s->sum[0] += position * position;
    s->sum[1] += angle * angle;
    s->max[0] = position > s->max[0] ? position : s->max[0];
    s->max[1] = angle > s->max[1] ? angle : s->max[1];
    ++s->n;
}

int main(int argc, char **argv)
{
    double nominal[RPR3_NUM_PARAMS], truth[RPR3_NUM_PARAMS];
    const char *perturbed[] = {"m1", "m2", "m3", "J1", "J2", "J3"};
    const double factor[] = {1.03, 0.96, 1.05, 1.04, 0.97, 1.05};
    const char *name = "rectilinear", *params_file = "paper.params";
    double seconds = DURATION, offset = 0.0; /* s, mm */
    const int revolute = strcmp(RPR3_ACTUATION, "revolute") == 0;
    const double dt = 1.0 / RATE_HZ;
    long steps;
    const long transient = (long)(TRANSIENT * RATE_HZ + 0.5);
    const char *unit = revolute ? "N m" : "N";
    struct controller ctl;
    struct stats after = {{0.0, 0.0}, {0.0, 0.0}, 0}, overall = after, estimate = after;
    double q[3], qd[3] = {0.0, 0.0, 0.0}, velocity_sq[2] = {0.0, 0.0};
    double tau_sq = 0.0, dtau_sq = 0.0, dtau_max = 0.0, previous_tau[3] = {0.0, 0.0, 0.0};
    double *latency;
    long step, counts[3], n_split = 0, n_whole = 0;
    int k;

    if (parse_arguments(argc, argv, &params_file, &name, &seconds, &offset) != 0
        || read_params(params_file, nominal) < 0) {
        fprintf(stderr, "usage: control_loop [--params FILE] [--trajectory rectilinear|rotation] "
                        "[--seconds T] [--offset MM] [rectilinear|rotation]\n");
        return 2;
    }
    steps = (long)(seconds * RATE_HZ + 0.5);
    memset(&ctl, 0, sizeof ctl);
    if (strcmp(name, "rectilinear") == 0) {
        ctl.amplitude[0] = 0.05, ctl.amplitude[1] = -0.05, ctl.amplitude[2] = 0.0;
    } else if (strcmp(name, "rotation") == 0) {
        ctl.amplitude[0] = 0.0, ctl.amplitude[1] = 0.0, ctl.amplitude[2] = PI / 6.0;
    } else {
        fprintf(stderr, "control_loop: unknown trajectory %s\n", name);
        return 2;
    }
    if (steps <= 0 || !isfinite(offset)) {
        fprintf(stderr, "control_loop: the duration must be positive, the offset finite\n");
        return 2;
    }
    memcpy(truth, nominal, sizeof truth);
    for (k = 0; k < 6; ++k) {
        truth[index_of(rpr3_param_names, RPR3_NUM_PARAMS, perturbed[k])] *= factor[k];
    }
    ctl.params = nominal;
    ctl.resolution = revolute ? 2.0 * PI / COUNTS_PER_REV : METRES_PER_COUNT;
    ctl.alpha = 1.0 - exp(-2.0 * PI * RATE_CUTOFF_HZ / RATE_HZ);
    q[0] = 1e-3 * offset, q[1] = 0.0 - 1e-3 * offset, q[2] = 0.0; /* the controller assumes home */
    /* fk and rest of the split ticks, whole of the others: at most steps values each */
    latency = malloc(3 * (size_t)steps * sizeof *latency);
    if (latency == NULL) {
        fprintf(stderr, "control_loop: out of memory\n");
        return 1;
    }

    for (step = 0; step < steps; ++step) {
        const double t = step * dt;
        double ns[3] = {0.0, 0.0, 0.0}, q_d[3], qd_d[3], qdd_d[3], dq[3];
        if (encoders(truth, q, ctl.resolution, counts) != 0) {
            fprintf(stderr, "control_loop: the plant reached a singular pose at t = %g s\n", t);
            free(latency);
            return 1;
        }
        controller_tick(&ctl, counts, t, step % 2 == 0, ns);
        if (step % 2 == 0) { /* a split tick */
            latency[n_split] = ns[0];
            latency[steps + n_split] = ns[1];
            ++n_split;
        } else {
            latency[2 * steps + n_whole] = ns[2];
            ++n_whole;
        }

        for (k = 0; k < 3; ++k) {
            dq[k] = ctl.qd[k] - qd[k];
            tau_sq += ctl.tau[k] * ctl.tau[k];
            if (step > 0) {
                const double d = fabs(ctl.tau[k] - previous_tau[k]);
                dtau_sq += d * d;
                dtau_max = d > dtau_max ? d : dtau_max;
            }
            previous_tau[k] = ctl.tau[k];
        }
        add(&estimate, hypot(ctl.q1[0] - q[0], ctl.q1[1] - q[1]), fabs(ctl.q1[2] - q[2]));
        velocity_sq[0] += dq[0] * dq[0] + dq[1] * dq[1];
        velocity_sq[1] += dq[2] * dq[2];

        if (plant_step(truth, q, qd, ctl.tau, dt) != 0) {
            fprintf(stderr, "control_loop: the plant reached a singular pose at t = %g s\n", t);
            free(latency);
            return 1;
        }
        reference(ctl.amplitude, t + dt, q_d, qd_d, qdd_d);
        add(&overall, hypot(q[0] - q_d[0], q[1] - q_d[1]), fabs(q[2] - q_d[2]));
        if (step >= transient) {
            add(&after, hypot(q[0] - q_d[0], q[1] - q_d[1]), fabs(q[2] - q_d[2]));
        }
    }

    printf("trajectory %s, %ld ticks at %d Hz, %s actuation, start offset (%.3f, %.3f) mm\n",
           name, steps, RATE_HZ, RPR3_ACTUATION, offset, 0.0 - offset);
    if (revolute) {
        printf("plant: masses and inertias off by 3-5%%, RK4 at %d Hz; encoders %d counts/rev "
               "(%.1f urad/count), rates from count differences, low-pass %g Hz\n",
               SUBSTEPS * RATE_HZ, COUNTS_PER_REV, ctl.resolution * 1e6, RATE_CUTOFF_HZ);
    } else {
        printf("plant: masses and inertias off by 3-5%%, RK4 at %d Hz; encoders %g um/count, "
               "rates from count differences, low-pass %g Hz\n",
               SUBSTEPS * RATE_HZ, METRES_PER_COUNT * 1e6, RATE_CUTOFF_HZ);
    }
    if (after.n > 0) {
        printf("tracking error after %g ms: position rms %.4f mm, max %.4f mm; angle rms %.4f "
               "mrad, max %.4f mrad\n",
               TRANSIENT * 1e3, sqrt(after.sum[0] / after.n) * 1e3, after.max[0] * 1e3,
               sqrt(after.sum[1] / after.n) * 1e3, after.max[1] * 1e3);
    }
    printf("tracking error overall: position rms %.4f mm, max %.4f mm; angle rms %.4f mrad, max "
           "%.4f mrad\n",
           sqrt(overall.sum[0] / overall.n) * 1e3, overall.max[0] * 1e3,
           sqrt(overall.sum[1] / overall.n) * 1e3, overall.max[1] * 1e3);
    printf("estimate error: pose max %.4f mm, %.4f mrad; velocity rms %.3f mm/s, %.3f mrad/s\n",
           estimate.max[0] * 1e3, estimate.max[1] * 1e3, sqrt(velocity_sq[0] / steps) * 1e3,
           sqrt(velocity_sq[1] / steps) * 1e3);
    printf("efforts: rms %.3f %s; change per tick rms %.4f %s, max %.4f %s\n",
           sqrt(tau_sq / (3.0 * steps)), unit, steps > 1 ? sqrt(dtau_sq / (3.0 * (steps - 1))) : 0.0,
           unit, dtau_max, unit);
    printf("failed calls: forward kinematics %ld, jacobian %ld, dynamics %ld\n", ctl.failed_fk,
           ctl.failed_jacobian, ctl.failed_dynamics);
    print_latency("forward kinematics", latency, n_split);
    print_latency("rest of the tick", latency + steps, n_split);
    print_latency("whole tick", latency + 2 * steps, n_whole);
    free(latency);
    return ctl.failed_fk || ctl.failed_jacobian || ctl.failed_dynamics ? 1 : 0;
}
