/* dd.h -- PRIVATE to src/paraxial (not part of the engine's public face): double-double
 * arithmetic (a value is hi + lo, |lo| <= ulp(hi)/2) built on fma, for the system
 * matrix and the cancellation-prone sums of the first-order formulas.  The build uses
 * -ffp-contract=off, so every fma here is explicit and nothing else gets contracted. */
#ifndef PX_DD_H
#define PX_DD_H
#include <math.h>

typedef struct dd { double hi, lo; } dd;

static inline dd dd_of(double x) { dd r = {x, 0.0}; return r; }
static inline double dd_val(dd x) { return x.hi + x.lo; }

static inline dd dd_two_sum(double a, double b)
{
    dd r;
    double bb;
    r.hi = a + b;
    bb = r.hi - a;
    r.lo = (a - (r.hi - bb)) + (b - bb);
    return r;
}

static inline dd dd_fast(double a, double b)   /* |a| >= |b| */
{
    dd r;
    r.hi = a + b;
    r.lo = b - (r.hi - a);
    return r;
}

static inline dd dd_two_prod(double a, double b)
{
    dd r;
    r.hi = a * b;
    r.lo = fma(a, b, -r.hi);
    return r;
}

static inline dd dd_add(dd x, dd y)
{
    dd s = dd_two_sum(x.hi, y.hi), t = dd_two_sum(x.lo, y.lo);
    s.lo += t.hi;
    s = dd_fast(s.hi, s.lo);
    s.lo += t.lo;
    return dd_fast(s.hi, s.lo);
}

static inline dd dd_neg(dd x) { dd r = {-x.hi, -x.lo}; return r; }
static inline dd dd_sub(dd x, dd y) { return dd_add(x, dd_neg(y)); }

static inline dd dd_mul(dd x, dd y)
{
    dd p = dd_two_prod(x.hi, y.hi);
    p.lo += x.hi * y.lo + x.lo * y.hi;
    return dd_fast(p.hi, p.lo);
}

static inline dd dd_mul_d(dd x, double y)
{
    dd p = dd_two_prod(x.hi, y);
    p.lo += x.lo * y;
    return dd_fast(p.hi, p.lo);
}

static inline dd dd_div_d(dd x, double y)
{
    double q1 = x.hi / y, q2;
    dd p = dd_two_prod(q1, y);
    dd r = dd_sub(x, p);
    q2 = (r.hi + r.lo) / y;
    return dd_fast(q1, q2);
}

/* x / y rounded to double (correct to about 1 ulp). */
static inline double dd_ratio(dd x, dd y) { return dd_val(x) / dd_val(y); }

#endif
