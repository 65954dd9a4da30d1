/* MuJoCo's mj_forward on a spatial robot as rpr3gen exports it, at the states of a motion.
 *
 * Built by benchmarks/harness/mujoco.py against the MuJoCo library of the `mujoco` Python
 * package (its headers and libmujoco), with the runtime's flags. Usage:
 *
 *   mujoco MODEL.xml STATES N PASSES REPEATS
 *
 * MODEL.xml: `rpr3gen export --format mjcf`; STATES: N states, each its qpos (nq), qvel (nv)
 * and ctrl (nu) in turn, raw float64 (harness/mujoco.py makes the legs consistent with the
 * platform's pose and rates). A round sets each state in turn and calls mj_forward on it, the N
 * states PASSES times over, back to back: MuJoCo's warm start carries from one state to the
 * next, as in a simulation. Prints a JSON line (timing.h): mj_forward/single in ns per call over
 * the REPEATS rounds (after one untimed round), and mj_forward/copy, the states' copy alone.
 */
#include "timing.h"

#include <mujoco/mujoco.h>

static void set_state(const mjModel *m, mjData *d, const double *s)
{
    memcpy(d->qpos, s, (size_t)m->nq * sizeof(double));
    memcpy(d->qvel, s + m->nq, (size_t)m->nv * sizeof(double));
    memcpy(d->ctrl, s + m->nq + m->nv, (size_t)m->nu * sizeof(double));
}

int main(int argc, char **argv)
{
    char error[1000];
    mjModel *m;
    mjData *d;
    double *states, *call_ns, *copy_ns, sink = 0.0;
    size_t n, passes, repeats, width, r, p, i;
    FILE *f;
    if (argc < 6) {
        fprintf(stderr, "usage: mujoco MODEL.xml STATES N PASSES REPEATS\n");
        return 2;
    }
    m = mj_loadXML(argv[1], NULL, error, sizeof error);
    if (m == NULL) {
        fprintf(stderr, "mujoco: %s\n", error);
        return 2;
    }
    d = mj_makeData(m);
    n = (size_t)strtoull(argv[3], NULL, 10);
    passes = (size_t)strtoull(argv[4], NULL, 10);
    repeats = (size_t)strtoull(argv[5], NULL, 10);
    width = (size_t)(m->nq + m->nv + m->nu);
    states = malloc(n * width * sizeof(double));
    call_ns = malloc(2 * repeats * sizeof(double));
    copy_ns = call_ns + repeats;
    f = fopen(argv[2], "rb");
    if (states == NULL || call_ns == NULL || f == NULL
        || fread(states, sizeof(double), n * width, f) != n * width) {
        fprintf(stderr, "mujoco: cannot read %zu states from %s\n", n, argv[2]);
        return 2;
    }
    fclose(f);
    for (r = 0; r <= repeats; ++r) { /* round 0 untimed: the warm-up */
        double t0 = timing_now_ns(), t1;
        for (p = 0; p < passes; ++p) {
            for (i = 0; i < n; ++i) {
                set_state(m, d, states + i * width);
                mj_forward(m, d);
                sink += d->qacc[0];
            }
        }
        t1 = timing_now_ns();
        for (p = 0; p < passes; ++p) {
            for (i = 0; i < n; ++i) {
                set_state(m, d, states + i * width);
                sink += d->qpos[0];
            }
        }
        if (r > 0) {
            call_ns[r - 1] = (t1 - t0) / (double)(n * passes);
            copy_ns[r - 1] = (timing_now_ns() - t1) / (double)(n * passes);
        }
    }
    timing_summary("mj_forward/single", "ns", call_ns, repeats);
    timing_summary("mj_forward/copy", "ns", copy_ns, repeats);
    printf("{\"name\": \"mj_forward/model\", \"nq\": %d, \"nv\": %d, \"neq\": %d, \"sink\": %g}\n",
           m->nq, m->nv, m->neq, sink);
    mj_deleteData(d);
    mj_deleteModel(m);
    return 0;
}
