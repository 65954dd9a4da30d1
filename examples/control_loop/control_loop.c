/* 1 kHz computed-torque tracking of the paper's trajectory with the generated inverse dynamics.
 *
 * The controller feeds the desired acceleration plus a PD correction to rpr3_inverse_dynamics
 * with the nominal model; the plant is the same robot with true masses and inertias a few
 * percent off, integrated forward from the motor torques (its dynamics are affine in the
 * acceleration, so four inverse-dynamics calls give the mass matrix and the bias). Prints the
 * tracking error and the latency distribution of the controller's call.
 *
 *   make && ./control_loop paper.params [rectilinear|rotation] [seconds]
 *
 * paper.params: "name value" lines, e.g. from `rpr3gen params > paper.params`.
 */
#define _POSIX_C_SOURCE 199309L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rpr3.h"

#define PI 3.14159265358979323846
#define RATE_HZ 1000
#define SUBSTEPS 4

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

/* Paper eq. (3): q/q* = 1 - cos(pi t / T), and its derivatives. */
static void reference(const double *amplitude, double t, double duration, double *q, double *qd,
                      double *qdd)
{
    const double w = PI / duration;
    int k;
    for (k = 0; k < 3; ++k) {
        q[k] = amplitude[k] * (1.0 - cos(w * t));
        qd[k] = amplitude[k] * w * sin(w * t);
        qdd[k] = amplitude[k] * w * w * cos(w * t);
    }
}

/* Plant: the platform acceleration produced by the motor torques tau, from the true model. */
static int forward_dynamics(const double *params, const int *actuator, const double *q,
                            const double *qd, const double *tau, double *qdd)
{
    double out[RPR3_NUM_OUTPUTS];
    double bias[3], a[3][3], rhs[3], det;
    double unit[3] = {0.0, 0.0, 0.0};
    int i, j;
    if (rpr3_inverse_dynamics(params, q, qd, unit, out) != RPR3_OK) {
        return -1;
    }
    for (i = 0; i < 3; ++i) {
        bias[i] = out[actuator[i]];
    }
    for (j = 0; j < 3; ++j) {
        unit[j] = 1.0;
        if (rpr3_inverse_dynamics(params, q, qd, unit, out) != RPR3_OK) {
            return -1;
        }
        unit[j] = 0.0;
        for (i = 0; i < 3; ++i) {
            a[i][j] = out[actuator[i]] - bias[i];
        }
    }
    for (i = 0; i < 3; ++i) {
        rhs[i] = tau[i] - bias[i];
    }
    det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (j = 0; j < 3; ++j) { /* Cramer's rule */
        double m[3][3];
        memcpy(m, a, sizeof m);
        for (i = 0; i < 3; ++i) {
            m[i][j] = rhs[i];
        }
        qdd[j] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                  - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                  + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) / det;
    }
    return 0;
}

static int compare(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    double nominal[RPR3_NUM_PARAMS], truth[RPR3_NUM_PARAMS];
    const char *perturbed[] = {"m1", "m2", "m3", "J1", "J2", "J3"};
    const double factor[] = {1.03, 0.96, 1.05, 1.04, 0.97, 1.05};
    double amplitude[3];
    const char *name = argc > 2 ? argv[2] : "rectilinear";
    const double duration = 3.0;
    const double seconds = argc > 3 ? atof(argv[3]) : duration;
    const double dt = 1.0 / RATE_HZ, kp = 900.0, kd = 60.0;
    const long steps = (long)(seconds * RATE_HZ + 0.5);
    int actuator[3];
    double q[3] = {0.001, -0.001, 0.0}, qd[3] = {0.0, 0.0, 0.0};
    double *latency;
    double max_pos = 0.0, max_ang = 0.0, sum_pos = 0.0, final_pos = 0.0;
    long step, failed = 0;
    int i, k;

    if (argc < 2 || read_params(argv[1], nominal) < 0) {
        fprintf(stderr, "usage: control_loop PARAMS_FILE [rectilinear|rotation] [seconds]\n");
        return 2;
    }
    if (strcmp(name, "rectilinear") == 0) {
        amplitude[0] = 0.05, amplitude[1] = -0.05, amplitude[2] = 0.0;
    } else if (strcmp(name, "rotation") == 0) {
        amplitude[0] = 0.0, amplitude[1] = 0.0, amplitude[2] = PI / 6.0;
    } else {
        fprintf(stderr, "control_loop: unknown trajectory %s\n", name);
        return 2;
    }
    if (steps <= 0) {
        fprintf(stderr, "control_loop: the duration must be positive\n");
        return 2;
    }
    memcpy(truth, nominal, sizeof truth);
    for (k = 0; k < 6; ++k) {
        truth[index_of(rpr3_param_names, RPR3_NUM_PARAMS, perturbed[k])] *= factor[k];
    }
    for (i = 0; i < 3; ++i) { /* the actuated joint's load of each leg */
        char column[16];
        sprintf(column, "%s_%c", strcmp(RPR3_ACTUATION, "revolute") == 0 ? "m10" : "f21z",
                "ABC"[i]);
        actuator[i] = index_of(rpr3_output_names, RPR3_NUM_OUTPUTS, column);
    }
    latency = malloc((size_t)steps * sizeof *latency);
    if (latency == NULL) {
        return 1;
    }

    for (step = 0; step < steps; ++step) {
        const double t = step * dt;
        double q_des[3], qd_des[3], qdd_des[3], qdd_cmd[3], out[RPR3_NUM_OUTPUTS], tau[3];
        double pos;
        struct timespec start, stop;
        reference(amplitude, t, duration, q_des, qd_des, qdd_des);
        for (k = 0; k < 3; ++k) {
            qdd_cmd[k] = qdd_des[k] + kd * (qd_des[k] - qd[k]) + kp * (q_des[k] - q[k]);
        }
        clock_gettime(CLOCK_MONOTONIC, &start);
        if (rpr3_inverse_dynamics(nominal, q, qd, qdd_cmd, out) != RPR3_OK) {
            ++failed;
            continue;
        }
        clock_gettime(CLOCK_MONOTONIC, &stop);
        latency[step] = (stop.tv_sec - start.tv_sec) * 1e9 + (stop.tv_nsec - start.tv_nsec);
        for (i = 0; i < 3; ++i) {
            tau[i] = out[actuator[i]];
        }
        for (k = 0; k < SUBSTEPS; ++k) { /* semi-implicit Euler */
            double acc[3];
            if (forward_dynamics(truth, actuator, q, qd, tau, acc) != 0) {
                fprintf(stderr, "control_loop: the plant reached a singular pose at t = %g s\n", t);
                free(latency);
                return 1;
            }
            for (i = 0; i < 3; ++i) {
                qd[i] += acc[i] * dt / SUBSTEPS;
                q[i] += qd[i] * dt / SUBSTEPS;
            }
        }
        reference(amplitude, t + dt, duration, q_des, qd_des, qdd_des);
        pos = hypot(q[0] - q_des[0], q[1] - q_des[1]);
        max_pos = pos > max_pos ? pos : max_pos;
        max_ang = fabs(q[2] - q_des[2]) > max_ang ? fabs(q[2] - q_des[2]) : max_ang;
        sum_pos += pos * pos;
        final_pos = pos;
    }
    qsort(latency, (size_t)steps, sizeof *latency, compare);
    printf("trajectory %s, %ld steps at %d Hz, %s actuation, plant masses off by 3-5%%\n", name,
           steps, RATE_HZ, RPR3_ACTUATION);
    printf("tracking error: position max %.4f mm, rms %.4f mm, final %.4f mm; angle max %.4f mrad\n",
           max_pos * 1e3, sqrt(sum_pos / steps) * 1e3, final_pos * 1e3, max_ang * 1e3);
    printf("rpr3_inverse_dynamics latency: p50 %.0f ns, p99 %.0f ns, max %.0f ns; failed calls %ld\n",
           latency[steps / 2], latency[(long)(0.99 * (steps - 1))], latency[steps - 1], failed);
    free(latency);
    return failed ? 1 : 0;
}
