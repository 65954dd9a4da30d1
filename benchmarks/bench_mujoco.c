/* C timing harness of the MuJoCo peer (run by benchmarks/run.py, section "Control model",
 * through benchmarks/rpr3bench/charness.py): mj_forward and mj_step of the paper's robot as
 * tests/mujoco_peer.py builds it, called from C, so that they compare with the C figures of
 * bench_control.c without the Python bindings' overhead.
 *
 * Build against the headers and the library of the mujoco Python package:
 *   cc -std=c11 -O2 -I .../mujoco/include benchmarks/bench_mujoco.c \
 *      .../mujoco/libmujoco.so.X -Wl,-rpath,.../mujoco -o bench_mujoco
 *
 * Usage:
 *   bench_mujoco MODEL.xml STATE CALLS REPEATS
 *     MODEL.xml  the MJCF (tests/mujoco_peer.build_mjcf), with its timestep and integrator
 *     STATE      text: nq nv nu, then qpos (nq), qvel (nv), ctrl (nu) values: a consistent
 *                state (tests/mujoco_peer.set_state) and the efforts
 *     CALLS      calls per timed pass
 *     REPEATS    timed passes of each call (after one untimed warm-up); median and best
 *
 * Prints "key value" lines, ns per call: mj_forward_{best,med} (the same state each call), and
 * mj_step_{best,med} (CALLS steps from the state, restored before each pass).
 */
#define _POSIX_C_SOURCE 199309L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

#define MAX_REPEATS 1001

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e9 * (double)ts.tv_sec + (double)ts.tv_nsec;
}

static int compare(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void report(const char *name, double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare);
    printf("%s_best %.1f\n", name, v[0]);
    printf("%s_med %.1f\n", name, n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

static void restore(const mjModel *m, mjData *d, const double *qpos, const double *qvel,
                    const double *ctrl)
{
    mj_resetData(m, d);
    memcpy(d->qpos, qpos, sizeof(double) * (size_t)m->nq);
    memcpy(d->qvel, qvel, sizeof(double) * (size_t)m->nv);
    memcpy(d->ctrl, ctrl, sizeof(double) * (size_t)m->nu);
}

int main(int argc, char **argv)
{
    static double forward[MAX_REPEATS], step[MAX_REPEATS];
    char error[1000] = "";
    double *qpos, *qvel, *ctrl, t0;
    int nq, nv, nu, k, r, calls, repeats;
    mjModel *m;
    mjData *d;
    FILE *f;

    if (argc != 5) {
        fprintf(stderr, "usage: %s MODEL.xml STATE CALLS REPEATS\n", argv[0]);
        return 2;
    }
    calls = atoi(argv[3]);
    repeats = atoi(argv[4]);
    if (calls < 1 || repeats < 1 || repeats > MAX_REPEATS) {
        fprintf(stderr, "bench_mujoco: bad CALLS or REPEATS\n");
        return 2;
    }
    m = mj_loadXML(argv[1], NULL, error, sizeof error);
    if (m == NULL) {
        fprintf(stderr, "bench_mujoco: %s\n", error);
        return 2;
    }
    f = fopen(argv[2], "r");
    if (f == NULL || fscanf(f, "%d %d %d", &nq, &nv, &nu) != 3 || nq != m->nq || nv != m->nv
        || nu != m->nu) {
        fprintf(stderr, "bench_mujoco: %s does not match the model\n", argv[2]);
        return 2;
    }
    qpos = malloc(sizeof(double) * (size_t)(nq + nv + nu));
    qvel = qpos + nq;
    ctrl = qvel + nv;
    for (k = 0; k < nq + nv + nu; ++k) {
        if (fscanf(f, "%lf", qpos + k) != 1) {
            fprintf(stderr, "bench_mujoco: %s: too few values\n", argv[2]);
            return 2;
        }
    }
    fclose(f);
    d = mj_makeData(m);
    for (r = -1; r < repeats; ++r) {
        restore(m, d, qpos, qvel, ctrl);
        t0 = now_ns();
        for (k = 0; k < calls; ++k) {
            mj_forward(m, d);
        }
        if (r >= 0) {
            forward[r] = (now_ns() - t0) / calls;
        }
        restore(m, d, qpos, qvel, ctrl);
        mj_forward(m, d);
        t0 = now_ns();
        for (k = 0; k < calls; ++k) {
            mj_step(m, d);
        }
        if (r >= 0) {
            step[r] = (now_ns() - t0) / calls;
        }
    }
    printf("mujoco %s\n", mj_versionString());
    printf("nq %ld\n", (long)m->nq);
    printf("timestep %g\n", m->opt.timestep);
    printf("integrator %d\n", m->opt.integrator);
    printf("calls %d\n", calls);
    printf("repeats %d\n", repeats);
    printf("final_time %g\n", d->time);
    report("mj_forward", forward, repeats);
    report("mj_step", step, repeats);
    mj_deleteData(d);
    mj_deleteModel(m);
    free(qpos);
    return 0;
}
