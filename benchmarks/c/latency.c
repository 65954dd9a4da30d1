/* The latency of each operation a generated kernel's chain is made of, on this machine.
 *
 * Built by benchmarks/harness/cbench.py with the runtime's flags, including a variant's rpr3.c
 * (its math kernels rpr3_sin, rpr3_cos, rpr3_atan2, rpr3_fmin, rpr3_rint are static). Usage:
 *
 *   latency N REPEATS
 *
 * Each figure is a loop in which every operation takes the previous one's result, so nothing
 * overlaps: its time per turn is the operation's latency (the loop's own counter runs beside
 * it). The functions are measured inside x = f(x) * a + b, which keeps x in their usual range
 * (the single call's fast paths: |x| < pi/4 for sin and cos), and that loop's multiply-add is
 * measured alone and subtracted. Prints JSON lines (timing.h): latency/NAME in ns, for the
 * names of benchmarks/harness/chain.py's LATENCIES. A math kernel that this rpr3.c does not
 * define (a Delta's has no sine) is left out: cbench.py passes -DLATENCY_NAME for each it has.
 */
#include "timing.h"

#include "rpr3.c"

/* Keeps x in a register the compiler must compute, so no loop is folded away. */
#define KEEP(x) __asm__ volatile("" : "+x"(x))

typedef double (*chain_fn)(double x, size_t n);

static double chain_add(double x, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        x = x + 0.5;
        KEEP(x);
    }
    return x;
}

static double chain_mul(double x, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        x = x * 1.0000001;
        KEEP(x);
    }
    return x;
}

static double chain_div(double x, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        x = 1.7 / x;
        KEEP(x);
    }
    return x;
}

/* x = g(x) * 0.25 + 0.25: the frame of every function's chain, measured alone as "frame". */
#define FRAMED(name, call)                                                                         \
    static double chain_##name(double x, size_t n)                                                 \
    {                                                                                              \
        size_t i;                                                                                  \
        for (i = 0; i < n; ++i) {                                                                  \
            x = (call) * 0.25 + 0.25;                                                              \
            KEEP(x);                                                                               \
        }                                                                                          \
        return x;                                                                                  \
    }

FRAMED(frame, x)
FRAMED(sqrt, sqrt(x))
#ifdef LATENCY_SIN
FRAMED(sin, rpr3_sin(x))
#endif
#ifdef LATENCY_COS
FRAMED(cos, rpr3_cos(x))
#endif
#ifdef LATENCY_ATAN2
FRAMED(atan2, rpr3_atan2(x, 0.7))
#endif
#ifdef LATENCY_FMIN
FRAMED(fmin, rpr3_fmin(x, 0.9))
#endif
#ifdef LATENCY_RINT
FRAMED(rint, rpr3_rint(x * 8.0) * 0.125) /* two multiplies more: subtracted below */
#endif

/* Time per turn of a chain, ns: the best pass of `repeats` after a warm-up. */
static double per_turn(chain_fn chain, size_t n, size_t repeats, double *sink)
{
    double best = 0.0;
    size_t r;
    for (r = 0; r <= repeats; ++r) {
        const double start = timing_now_ns();
        *sink += chain(0.3, n);
        const double ns = (timing_now_ns() - start) / (double)n;
        if (r == 1 || (r > 1 && ns < best)) {
            best = ns; /* pass 0 warms up */
        }
    }
    return best;
}

/* A latency too small to tell from the frame's prints as 0 (never negative). */
static void report(const char *name, double ns)
{
    ns = ns > 0.0 ? ns : 0.0;
    printf("{\"name\": \"latency/%s\", \"unit\": \"ns\", \"min\": %.4g}\n", name, ns);
}

int main(int argc, char **argv)
{
    const size_t n = argc > 1 ? (size_t)strtoull(argv[1], NULL, 10) : 1000000;
    const size_t repeats = argc > 2 ? (size_t)strtoull(argv[2], NULL, 10) : 5;
    double sink = 0.0;
    (void)timing_summary; /* timing.h's, for the benchmarks that report percentiles */
    const double add = per_turn(chain_add, n, repeats, &sink);
    const double mul = per_turn(chain_mul, n, repeats, &sink);
    const double frame = per_turn(chain_frame, n, repeats, &sink);
    report("add", add);
    report("mul", mul);
    report("div", per_turn(chain_div, n, repeats, &sink));
    report("sqrt", per_turn(chain_sqrt, n, repeats, &sink) - frame);
#ifdef LATENCY_SIN
    report("sin", per_turn(chain_sin, n, repeats, &sink) - frame);
#endif
#ifdef LATENCY_COS
    report("cos", per_turn(chain_cos, n, repeats, &sink) - frame);
#endif
#ifdef LATENCY_ATAN2
    report("atan2", per_turn(chain_atan2, n, repeats, &sink) - frame);
#endif
#ifdef LATENCY_FMIN
    report("fmin", per_turn(chain_fmin, n, repeats, &sink) - frame);
#endif
#ifdef LATENCY_RINT
    report("rint", per_turn(chain_rint, n, repeats, &sink) - frame - 2.0 * mul);
#endif
    fprintf(stderr, "latency: sink %g\n", sink);
    return 0;
}
