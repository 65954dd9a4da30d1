/* The generated C's math kernels (rpr3_sin, rpr3_cos, rpr3_atan2, rpr3_rint, rpr3_fmin,
 * rpr3_fmax) against the C library, over their whole domain; run by test_c_math_kernels.py.
 *
 * Build: cc -std=c99 -O3 ... -I generated/VARIANT tests/c_math_kernels.c -lm
 * (the kernels are static: this file includes the generated source; the test includes instead
 * a copy of its includes and kernels alone, which compiles in a fraction of the time).
 *
 * Usage: c_math_kernels [SCALE]   the checks below (SCALE multiplies the random counts)
 *        c_math_kernels eval      reads hexadecimal doubles x from stdin, prints
 *                                 "x sin(x) cos(x)" by the kernels (for checks against mpmath)
 *
 * Prints one line per check: "NAME MAX_ULP COUNT WORST_X WORST_Y", the largest distance in
 * units in the last place between a kernel and libm over COUNT arguments, and where it is;
 * "NAME_mismatch COUNT" lines count exact-comparison failures (special values, signed zeros,
 * the fast path against the full kernel, the single call's finite test against isfinite).
 */
#include "rpr3.c"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned long long state = 0x9e3779b97f4a7c15ULL;

static unsigned long long next(void) /* xorshift64 */
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

static double uniform(void) /* [0, 1) */
{
    return (double)(next() >> 11) * 0x1p-53;
}

static double any_finite(void) /* a finite double with a uniform bit pattern */
{
    double x;
    do {
        unsigned long long u = next();
        memcpy(&x, &u, sizeof x);
    } while (!isfinite(x));
    return x;
}

static double in_binade(int e) /* a random double of exponent e (subnormal below -1022), signed */
{
    double x = ldexp(1.0 + uniform(), e);
    return next() & 1 ? -x : x;
}

/* Distance in ulps between two doubles (0 for two NaNs; huge for NaN against a number). */
static double ulps(double a, double b)
{
    long long ia, ib;
    if (isnan(a) || isnan(b)) {
        return isnan(a) && isnan(b) ? 0.0 : 1e300;
    }
    memcpy(&ia, &a, sizeof ia);
    memcpy(&ib, &b, sizeof ib);
    if (ia < 0) {
        ia = (long long)0x8000000000000000ULL - ia;
    }
    if (ib < 0) {
        ib = (long long)0x8000000000000000ULL - ib;
    }
    return ia > ib ? (double)(ia - ib) : (double)(ib - ia);
}

static int same(double a, double b) /* identical, or both NaN */
{
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

struct worst {
    const char *name;
    double ulps, x, y;
    long count;
};

static void note(struct worst *w, double got, double want, double x, double y)
{
    const double d = ulps(got, want);
    ++w->count;
    if (d > w->ulps) {
        w->ulps = d;
        w->x = x;
        w->y = y;
    }
}

static void print(const struct worst *w)
{
    printf("%s %.0f %ld %a %a\n", w->name, w->ulps, w->count, w->x, w->y);
}

static void trig(struct worst *s, struct worst *c, long *fast_mismatch, double x)
{
    note(s, rpr3_sin(x), sin(x), x, 0.0);
    note(c, rpr3_cos(x), cos(x), x, 0.0);
    if (fabs(x) < 0x1p20 && !(same(rpr3_sin_fast(x), rpr3_sin(x))
                              && same(rpr3_cos_fast(x), rpr3_cos(x)))) {
        ++*fast_mismatch;
    }
}

int main(int argc, char **argv)
{
    const double special[] = {0.0, -0.0, INFINITY, -INFINITY, NAN, 1.0, -1.0, 0x1p-1074,
                              -0x1p-1074, 0x1p-1022, DBL_MAX, -DBL_MAX, 0x1p20, -0x1p20,
                              1e22};
    const int nspecial = (int)(sizeof special / sizeof special[0]);
    const long scale = argc > 1 ? atol(argv[1]) : 1;
    struct worst s = {"sin", 0, 0, 0, 0}, c = {"cos", 0, 0, 0, 0}, a = {"atan2", 0, 0, 0, 0};
    struct worst r = {"rint", 0, 0, 0, 0}, mn = {"fmin", 0, 0, 0, 0}, mx = {"fmax", 0, 0, 0, 0};
    long fast_mismatch = 0, special_mismatch = 0, finite_mismatch = 0, k;
    int e, i, j;
    double x0;

    if (argc > 1 && strcmp(argv[1], "eval") == 0) {
        while (scanf("%la", &x0) == 1) {
            printf("%a %a %a\n", x0, rpr3_sin(x0), rpr3_cos(x0));
        }
        return 0;
    }
    /* sin, cos: a dense sweep of [-64 pi, 64 pi]; multiples of pi/2 and their neighbours up to
     * 2^22; every binade; uniform bit patterns (mostly huge); special values. */
    for (k = -2000000; k <= 2000000; ++k) {
        trig(&s, &c, &fast_mismatch, k * (64 * 3.141592653589793 / 2000000));
    }
    for (k = 1; k < 2800000; k += 7) {
        const double x = k * 1.5707963267948966;
        trig(&s, &c, &fast_mismatch, x);
        trig(&s, &c, &fast_mismatch, nextafter(x, 0.0));
        trig(&s, &c, &fast_mismatch, nextafter(x, INFINITY));
    }
    /* the full kernel's branch at |x| = pi/4 (no reduction below): 64 doubles on either
     * side, both signs, must give the fast path's bits */
    for (i = 0; i < 2; ++i) {
        double below = i ? -0.7853981633974483 : 0.7853981633974483, above = below;
        for (k = 0; k < 64; ++k) {
            trig(&s, &c, &fast_mismatch, below);
            trig(&s, &c, &fast_mismatch, above);
            below = nextafter(below, 0.0);
            above = nextafter(above, i ? -INFINITY : INFINITY);
        }
    }
    for (e = -1074; e <= 1023; ++e) {
        for (k = 0; k < 100 * scale; ++k) {
            trig(&s, &c, &fast_mismatch, in_binade(e));
        }
    }
    for (k = 0; k < 200000 * scale; ++k) {
        trig(&s, &c, &fast_mismatch, any_finite());
    }
    for (i = 0; i < nspecial; ++i) {
        trig(&s, &c, &fast_mismatch, special[i]);
        special_mismatch += !same(rpr3_sin(special[i]), sin(special[i]));
        special_mismatch += !same(rpr3_cos(special[i]), cos(special[i]))
                            && !(isnan(special[i]) && isnan(rpr3_cos(special[i])));
    }

    /* atan2: the unit square and its neighbourhood densely, pairs of binades, uniform bit
     * patterns, every pair of special values (signed zeros and infinities exactly). */
    for (i = -1000; i <= 1000; ++i) {
        for (j = -1000; j <= 1000; ++j) {
            note(&a, rpr3_atan2(i * 0.002, j * 0.002), atan2(i * 0.002, j * 0.002), i * 0.002,
                 j * 0.002);
        }
    }
    for (e = -1074; e <= 1023; e += 3) {
        for (k = 0; k < 200 * scale; ++k) {
            const double y = in_binade(e), x = in_binade((int)(uniform() * 2097) - 1074);
            note(&a, rpr3_atan2(y, x), atan2(y, x), y, x);
            note(&a, rpr3_atan2(x, y), atan2(x, y), x, y);
        }
    }
    for (k = 0; k < 500000 * scale; ++k) {
        const double y = any_finite(), x = any_finite();
        note(&a, rpr3_atan2(y, x), atan2(y, x), y, x);
    }
    for (i = 0; i < nspecial; ++i) {
        for (j = 0; j < nspecial; ++j) {
            const double y = special[i], x = special[j];
            note(&a, rpr3_atan2(y, x), atan2(y, x), y, x);
            if (y == 0.0 || isinf(y) || x == 0.0 || isinf(x) || isnan(x) || isnan(y)) {
                special_mismatch += !same(rpr3_atan2(y, x), atan2(y, x));
            }
        }
    }

    /* rint, fmin, fmax: exact. */
    for (k = 0; k < 1000000 * scale; ++k) {
        const double x = k % 2 ? any_finite() : (uniform() - 0.5) * ldexp(1.0, (int)(k % 60));
        const double y = any_finite();
        r.count++;
        if (!same(rpr3_rint(x), nearbyint(x))) {
            r.ulps = 1; /* any difference fails */
            r.x = x;
        }
        note(&mn, rpr3_fmin(x, y), fmin(x, y), x, y);
        note(&mx, rpr3_fmax(x, y), fmax(x, y), x, y);
    }
    for (i = 0; i < nspecial; ++i) {
        special_mismatch += !same(rpr3_rint(special[i]), nearbyint(special[i]));
        for (j = 0; j < nspecial; ++j) {
            const double x = special[i], y = special[j];
            if (!(x == 0.0 && y == 0.0)) { /* C99 leaves fmin(-0, +0)'s sign open */
                special_mismatch += !same(rpr3_fmin(x, y), fmin(x, y));
                special_mismatch += !same(rpr3_fmax(x, y), fmax(x, y));
            }
        }
    }

    /* rpr3_finite_values, the single call's exact test of its inputs and outputs, against
     * isfinite: each special value and 10^6 uniform bit patterns alone; rows of 53 values (the
     * inverse dynamics' outputs) finite but for one, at every position; rows of DBL_MAX, whose
     * sum overflows but whose values are finite. */
    for (i = 0; i < nspecial; ++i) {
        finite_mismatch += rpr3_finite_values(&special[i], 1) != (isfinite(special[i]) != 0);
    }
    for (k = 0; k < 1000000 * scale; ++k) {
        const unsigned long long bits = next();
        double x;
        memcpy(&x, &bits, sizeof x);
        finite_mismatch += rpr3_finite_values(&x, 1) != (isfinite(x) != 0);
    }
    {
        double row[53];
        for (j = 0; j < 53; ++j) {
            row[j] = DBL_MAX;
        }
        finite_mismatch += rpr3_finite_values(row, 53) != 1;
        for (i = 0; i < nspecial; ++i) {
            for (j = 0; j < 53; ++j) {
                int m;
                for (m = 0; m < 53; ++m) {
                    row[m] = any_finite();
                }
                row[j] = special[i];
                finite_mismatch += rpr3_finite_values(row, 53) != (isfinite(special[i]) != 0);
            }
        }
    }

    print(&s);
    print(&c);
    print(&a);
    print(&r);
    print(&mn);
    print(&mx);
    printf("fast_mismatch %ld\n", fast_mismatch);
    printf("special_mismatch %ld\n", special_mismatch);
    printf("finite_mismatch %ld\n", finite_mismatch);
    return 0;
}
