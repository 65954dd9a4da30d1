/* Every generated function of one variant against its floor: C single call, C batch.
 *
 * Built by benchmarks/cbench.py with functions.h, which it writes from the variant's manifest:
 * per function its floor loop (the libm calls its kernel makes, nothing else), its single-call
 * loop and its batch loop over chunks of CHUNK samples, and the table FUNCTIONS. Usage:
 *
 *   functions PARAMS DIR N REPEATS
 *
 * PARAMS: "name value" lines (`rpr3gen params`); DIR/NAME-INPUT.bin: N samples of each input
 * of function NAME, raw float64. Prints JSON lines (timing.h): NAME/floor, NAME/single,
 * NAME/batch in ns per sample, and NAME/agree (1 when single calls and the batch give the same
 * bits on the first CHUNK samples, NaN payloads aside) with the failed counts.
 */
#include "timing.h"

#include <math.h>

#include "rpr3.h"

#define CHUNK 1000
#define MAX_ARGS 4

struct function {
    const char *name;
    int n_in, n_out;
    int in_size[MAX_ARGS], out_size[MAX_ARGS];
    double (*floor)(const double *const *in, size_t n);
    size_t (*single)(const double *p, const double *const *in, size_t n, double *const *out,
                     size_t step);
    size_t (*batch)(const double *p, const double *const *in, size_t n, double *const *out);
};

#include "functions.h"

static double *read_doubles(const char *path, size_t count)
{
    double *data = malloc(count * sizeof(double));
    FILE *f = fopen(path, "rb");
    if (data == NULL || f == NULL || fread(data, sizeof(double), count, f) != count) {
        fprintf(stderr, "functions: cannot read %zu doubles from %s\n", count, path);
        exit(2);
    }
    fclose(f);
    return data;
}

static void read_params(const char *path, double *params)
{
    char name[64];
    double value;
    int k;
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        fprintf(stderr, "functions: cannot open %s\n", path);
        exit(2);
    }
    while (fscanf(f, "%63s %lf", name, &value) == 2) {
        for (k = 0; k < RPR3_NUM_PARAMS; ++k) {
            if (strcmp(rpr3_param_names[k], name) == 0) {
                params[k] = value;
            }
        }
    }
    fclose(f);
}

static void measure(const struct function *f, const double *params, const char *dir, size_t n,
                    size_t repeats)
{
    const double *in[MAX_ARGS];
    double *out[MAX_ARGS], *rows[MAX_ARGS], *floor_ns, *single_ns, *batch_ns;
    char path[4096], label[128];
    double sink = 0.0;
    size_t r, k, failed_single = 0, failed_batch = 0;
    int j, agree = 1;
    for (j = 0; j < f->n_in; ++j) {
        snprintf(path, sizeof path, "%s/%s-%d.bin", dir, f->name, j);
        in[j] = read_doubles(path, n * (size_t)f->in_size[j]);
    }
    for (j = 0; j < f->n_out; ++j) {
        out[j] = malloc(CHUNK * (size_t)f->out_size[j] * sizeof(double));
        rows[j] = malloc(CHUNK * (size_t)f->out_size[j] * sizeof(double));
    }
    floor_ns = malloc(3 * repeats * sizeof(double));
    single_ns = floor_ns + repeats;
    batch_ns = single_ns + repeats;
    sink += f->floor(in, n); /* warm-up */
    failed_single = f->single(params, in, n, out, 0);
    failed_batch = f->batch(params, in, n, out);
    for (r = 0; r < repeats; ++r) { /* the three loops interleaved: shared conditions */
        double t0 = timing_now_ns();
        sink += f->floor(in, n);
        floor_ns[r] = (timing_now_ns() - t0) / (double)n;
        t0 = timing_now_ns();
        f->single(params, in, n, out, 0);
        single_ns[r] = (timing_now_ns() - t0) / (double)n;
        t0 = timing_now_ns();
        f->batch(params, in, n, out);
        batch_ns[r] = (timing_now_ns() - t0) / (double)n;
    }
    f->single(params, in, CHUNK, rows, 1); /* single calls and the batch, bit for bit */
    f->batch(params, in, CHUNK, out);
    for (j = 0; j < f->n_out; ++j) { /* the same bits, or both NaN (of any payload) */
        for (k = 0; k < CHUNK * (size_t)f->out_size[j]; ++k) {
            const double a = out[j][k], b = rows[j][k];
            agree = agree && ((a != a && b != b) || memcmp(&a, &b, sizeof a) == 0);
        }
    }
    snprintf(label, sizeof label, "%s/floor", f->name);
    timing_summary(label, "ns", floor_ns, repeats);
    snprintf(label, sizeof label, "%s/single", f->name);
    timing_summary(label, "ns", single_ns, repeats);
    snprintf(label, sizeof label, "%s/batch", f->name);
    timing_summary(label, "ns", batch_ns, repeats);
    printf("{\"name\": \"%s/agree\", \"agree\": %d, \"failed_single\": %zu, \"failed_batch\": "
           "%zu, \"sink\": %g}\n",
           f->name, agree, failed_single, failed_batch, sink);
    for (j = 0; j < f->n_in; ++j) {
        free((void *)in[j]);
    }
    for (j = 0; j < f->n_out; ++j) {
        free(out[j]);
        free(rows[j]);
    }
    free(floor_ns);
}

int main(int argc, char **argv)
{
    double params[RPR3_NUM_PARAMS];
    size_t k, n, repeats;
    if (argc < 5) {
        fprintf(stderr, "usage: functions PARAMS DIR N REPEATS [NAME...]\n");
        return 2;
    }
    read_params(argv[1], params);
    n = (size_t)strtoull(argv[3], NULL, 10);
    repeats = (size_t)strtoull(argv[4], NULL, 10);
    for (k = 0; k < sizeof FUNCTIONS / sizeof FUNCTIONS[0]; ++k) {
        int wanted = argc == 5, a;
        for (a = 5; a < argc; ++a) {
            wanted = wanted || strcmp(argv[a], FUNCTIONS[k].name) == 0;
        }
        if (wanted) {
            measure(&FUNCTIONS[k], params, argv[2], n, repeats);
        }
    }
    return 0;
}
