// scene_dtoa.cpp -- the shortest decimal string that reads back (strtod) to the same
// double, for the hit and segment writers (scene_out.c): Debian's libdouble-conversion
// (Grisu3 with a bignum fallback: exact for every double) behind one C function.
// glibc's "%.17g" took 81 % of a trace that writes every hit; this takes a tenth of
// its time and writes fewer digits (0.1, not 0.10000000000000001).  No exception can
// leave: the converter only writes into the caller's buffer.
#include <double-conversion/double-conversion.h>

extern "C" int sc_dtoa(double v, char *buf);

// The %g-like layout: plain decimals from 1e-4 up to 1e17, else 1.5e-07-style
// exponents with their sign ("1e+20"); "inf", "-inf", "nan" as strtod and NumPy read
// them.  Stateless and const: safe from any thread.
static const double_conversion::DoubleToStringConverter conv(
    double_conversion::DoubleToStringConverter::EMIT_POSITIVE_EXPONENT_SIGN, "inf", "nan",
    'e', -4, 17, 0, 0);

// Writes the digits of v into buf (at least 32 bytes), NUL-terminated; returns the
// length.
extern "C" int sc_dtoa(double v, char *buf)
{
    double_conversion::StringBuilder sb(buf, 32);
    conv.ToShortest(v, &sb);
    int n = sb.position();
    sb.Finalize();
    return n;
}
