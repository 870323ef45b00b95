// scene_dtoa.cpp -- the shortest decimal string that reads back (strtod) to the same
// double, for the hit writer (scene_out.c): Debian's libdouble-conversion (Grisu3 with
// a bignum fallback: exact for every double) behind one C function.  glibc's "%.17g"
// took 81 % of a trace that writes every hit; this takes about a third of its time
// per number (measured on the triplet's hit values: 84-94 ns against 240-310 ns of
// CPU) and writes fewer digits (0.1, not 0.10000000000000001).  The digits come from
// DoubleToAscii (SHORTEST); the layout is done here, as the library's ToShortest
// would with these settings, without its string builder.  No exception can leave:
// nothing here throws.
#include <double-conversion/double-conversion.h>
#include <cmath>
#include <cstring>

extern "C" int sc_dtoa(double v, char *buf);

// The %g-like layout: plain decimals for exponents -4 to 16 (0.0001 .. 1e17), else
// 1.5e-7-style exponents with their sign (1e+20); "inf", "-inf", "nan" as strtod and
// NumPy read them; -0 keeps its sign.
enum { LOW = -4, HIGH = 17 };

// Writes the digits of v into buf (at least 32 bytes), NUL-terminated; returns the
// length.
extern "C" int sc_dtoa(double v, char *buf)
{
    char *p = buf;
    if (std::isnan(v)) { std::memcpy(buf, "nan", 4); return 3; }
    if (std::isinf(v)) {
        if (v < 0) *p++ = '-';
        std::memcpy(p, "inf", 4);
        return (int)(p - buf) + 3;
    }
    char d[20];
    bool sign;
    int len, point;
    double_conversion::DoubleToStringConverter::DoubleToAscii(
        v, double_conversion::DoubleToStringConverter::SHORTEST, 0, d, sizeof d, &sign, &len,
        &point);
    if (sign) *p++ = '-';
    int e = point - 1;                       // v = 0.d1d2... x 10^point = d1.d2... x 10^e
    if (e >= LOW && e < HIGH) {
        if (point <= 0) {                    // 0.000ddd
            *p++ = '0';
            *p++ = '.';
            for (int i = 0; i < -point; i++) *p++ = '0';
            std::memcpy(p, d, (size_t)len);
            p += len;
        } else if (point >= len) {           // ddd000
            std::memcpy(p, d, (size_t)len);
            p += len;
            for (int i = len; i < point; i++) *p++ = '0';
        } else {                             // dd.ddd
            std::memcpy(p, d, (size_t)point);
            p += point;
            *p++ = '.';
            std::memcpy(p, d + point, (size_t)(len - point));
            p += len - point;
        }
    } else {                                 // d.ddde+xx
        *p++ = d[0];
        if (len > 1) {
            *p++ = '.';
            std::memcpy(p, d + 1, (size_t)(len - 1));
            p += len - 1;
        }
        *p++ = 'e';
        *p++ = e < 0 ? '-' : '+';
        int a = e < 0 ? -e : e;
        if (a >= 100) *p++ = (char)('0' + a / 100);
        if (a >= 10) *p++ = (char)('0' + a / 10 % 10);
        *p++ = (char)('0' + a % 10);
    }
    *p = '\0';
    return (int)(p - buf);
}
