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
 *
 * The repeats run in rounds: each round times every function in turn (an untimed pass first,
 * which brings its inputs back into cache, then its floor, single and batch loops one after the
 * other), and each figure is the best of its rounds. So a function's repeats spread over the
 * whole program's run, not a fraction of a second of it: on a shared machine whose other tenants
 * slow it for seconds at a time, one slow spell no longer spoils every repeat of a function.
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

/* One function's inputs, outputs and timings across the rounds. */
struct bench {
    const struct function *f;
    const double *in[MAX_ARGS];
    double *out[MAX_ARGS], *rows[MAX_ARGS];
    double *floor_ns, *single_ns, *batch_ns;
    size_t failed_single, failed_batch;
    double sink;
};

/* Reads a function's inputs, allocates its outputs and runs each loop once untimed. */
static void prepare(struct bench *b, const struct function *f, const double *params,
                    const char *dir, size_t n, size_t repeats)
{
    char path[4096];
    int j;
    b->f = f;
    for (j = 0; j < f->n_in; ++j) {
        snprintf(path, sizeof path, "%s/%s-%d.bin", dir, f->name, j);
        b->in[j] = read_doubles(path, n * (size_t)f->in_size[j]);
    }
    for (j = 0; j < f->n_out; ++j) {
        b->out[j] = malloc(CHUNK * (size_t)f->out_size[j] * sizeof(double));
        b->rows[j] = malloc(CHUNK * (size_t)f->out_size[j] * sizeof(double));
    }
    b->floor_ns = malloc(3 * repeats * sizeof(double));
    b->single_ns = b->floor_ns + repeats;
    b->batch_ns = b->single_ns + repeats;
    b->sink = f->floor(b->in, n);
    b->failed_single = f->single(params, b->in, n, b->out, 0);
    b->failed_batch = f->batch(params, b->in, n, b->out);
}

/* Round r of a function: one untimed pass (its inputs back in cache after the other functions'
 * rounds), then its floor, single and batch loops timed one after the other. */
static void time_round(struct bench *b, const double *params, size_t n, size_t r)
{
    const struct function *f = b->f;
    double t0;
    f->single(params, b->in, n, b->out, 0);
    t0 = timing_now_ns();
    b->sink += f->floor(b->in, n);
    b->floor_ns[r] = (timing_now_ns() - t0) / (double)n;
    t0 = timing_now_ns();
    f->single(params, b->in, n, b->out, 0);
    b->single_ns[r] = (timing_now_ns() - t0) / (double)n;
    t0 = timing_now_ns();
    f->batch(params, b->in, n, b->out);
    b->batch_ns[r] = (timing_now_ns() - t0) / (double)n;
}

/* Checks single calls against the batch bit for bit, prints the function's lines, frees it. */
static void finish(struct bench *b, const double *params, size_t repeats)
{
    const struct function *f = b->f;
    char label[128];
    size_t k;
    int j, agree = 1;
    f->single(params, b->in, CHUNK, b->rows, 1); /* single calls and the batch, bit for bit */
    f->batch(params, b->in, CHUNK, b->out);
    for (j = 0; j < f->n_out; ++j) { /* the same bits, or both NaN (of any payload) */
        for (k = 0; k < CHUNK * (size_t)f->out_size[j]; ++k) {
            const double a = b->out[j][k], c = b->rows[j][k];
            agree = agree && ((a != a && c != c) || memcmp(&a, &c, sizeof a) == 0);
        }
    }
    snprintf(label, sizeof label, "%s/floor", f->name);
    timing_summary(label, "ns", b->floor_ns, repeats);
    snprintf(label, sizeof label, "%s/single", f->name);
    timing_summary(label, "ns", b->single_ns, repeats);
    snprintf(label, sizeof label, "%s/batch", f->name);
    timing_summary(label, "ns", b->batch_ns, repeats);
    printf("{\"name\": \"%s/agree\", \"agree\": %d, \"failed_single\": %zu, \"failed_batch\": "
           "%zu, \"sink\": %g}\n",
           f->name, agree, b->failed_single, b->failed_batch, b->sink);
    for (j = 0; j < f->n_in; ++j) {
        free((void *)b->in[j]);
    }
    for (j = 0; j < f->n_out; ++j) {
        free(b->out[j]);
        free(b->rows[j]);
    }
    free(b->floor_ns);
}

int main(int argc, char **argv)
{
    double params[RPR3_NUM_PARAMS];
    struct bench benches[sizeof FUNCTIONS / sizeof FUNCTIONS[0]];
    size_t k, r, n, repeats, count = 0;
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
            prepare(&benches[count++], &FUNCTIONS[k], params, argv[2], n, repeats);
        }
    }
    for (r = 0; r < repeats; ++r) { /* the functions in turn, each round: see the top */
        for (k = 0; k < count; ++k) {
            time_round(&benches[k], params, n, r);
        }
    }
    for (k = 0; k < count; ++k) {
        finish(&benches[k], params, repeats);
    }
    return 0;
}
