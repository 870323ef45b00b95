// scene_dtoa.cpp -- the shortest decimal string that reads back (strtod) to the same
// double, for the hit writer (scene_out.c), behind one C function.
// The digits: Dragonbox (Jeon 2020: the shortest correctly rounded significand and
// its exponent, exact for every double), as Debian's libfmt ships it (header-only
// use: nothing to link, nothing loaded at run time); with another fmt, or none,
// Debian's libdouble-conversion (Grisu3 with a bignum fallback, also exact).  The
// layout (%g-like) and the digits' text are written here: 8 digits at a time from a
// 2-digit table, fixed-size copies into the caller's slack, no string builder.
// Measured on the triplet's 11 million hit values (tests: every one against
// double-conversion's digits, and 2e7 random bit patterns): 34-60 ns a number, against
// 108-170 ns for double-conversion and 240-310 ns for glibc's "%.17g" (loaded 2-core
// EPYC); 25-27 ns with Dragonbox's whole table (below; best of 10 passes over 2 M of
// them, of which to_decimal 12.5, the 17 digits about 8).  Tried and slower (27-30
// ns): the 8 digits as one word by lanes (SWAR), and the layout from registers with
// blind 8-byte stores instead of copies out of the digit buffer.  No exception can
// leave: nothing here throws.
#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__has_include) && __has_include(<fmt/format.h>) && !defined(SC_DTOA_DC)
#define FMT_HEADER_ONLY
// the whole table of powers of ten (about 10 KB) rather than a third of it and a
// multiplication to make the others: to_decimal 16.5 -> 12.5 ns, a number 31 -> 25 ns
// on the triplet's hits (2 M values, best of 10, loaded 2-core EPYC); the same digits
#ifndef FMT_USE_FULL_CACHE_DRAGONBOX
#define FMT_USE_FULL_CACHE_DRAGONBOX 1
#endif
#include <fmt/format.h>
#if FMT_VERSION >= 80000 && FMT_VERSION < 130000   // dragonbox::to_decimal as in 8 .. 12
#define SC_DRAGONBOX 1
#endif
#endif
#include <double-conversion/double-conversion.h>

extern "C" int sc_dtoa(double v, char *buf);
extern "C" int sc_dtoa_dc(double v, char *buf);
extern "C" const char *sc_dtoa_name(void);

// The %g-like layout: plain decimals for exponents -4 to 16 (0.0001 .. 1e17), else
// 1.5e-7-style exponents with their sign (1e+20); "inf", "-inf", "nan" as strtod and
// NumPy read them; -0 keeps its sign.
enum { LOW = -4, HIGH = 17 };

// v's significant digits d[0..len) (at least 17 readable bytes at d) as v = 0.d x
// 10^point, written at p; returns the end.  Copies 17 bytes where it needs len: the
// caller's buffer has SC_DTOA_SLACK bytes beyond the longest number.
static inline char *layout(char *p, const char *d, int len, int point)
{
    int e = point - 1;
    if (e >= LOW && e < HIGH) {
        if (point <= 0) {                    // 0.000ddd
            std::memcpy(p, "0.0000", 6);
            p += 2 - point;
            std::memcpy(p, d, 17);
            p += len;
        } else if (point >= len) {           // ddd000
            std::memcpy(p, d, 17);
            p += len;
            for (int i = len; i < point; i++) *p++ = '0';
        } else {                             // dd.ddd
            std::memcpy(p, d, 17);
            p[point] = '.';
            std::memcpy(p + point + 1, d + point, 16);
            p += len + 1;
        }
    } else {                                 // d.ddde+xx
        *p++ = d[0];
        if (len > 1) {
            *p = '.';
            std::memcpy(p + 1, d + 1, 16);
            p += len;
        }
        *p++ = 'e';
        *p++ = e < 0 ? '-' : '+';
        int a = e < 0 ? -e : e;
        if (a >= 100) *p++ = (char)('0' + a / 100);
        if (a >= 10) *p++ = (char)('0' + a / 10 % 10);
        *p++ = (char)('0' + a % 10);
    }
    return p;
}

// nan, inf, -inf, 0, -0 at p (the sign of a zero or an infinity too); the end, or
// NULL for a finite non-zero v.
static inline char *special(double v, char *p)
{
    if (std::isnan(v)) { std::memcpy(p, "nan", 3); return p + 3; }
    if (std::signbit(v)) *p++ = '-';
    if (std::isinf(v)) { std::memcpy(p, "inf", 3); return p + 3; }
    if (v == 0) { *p++ = '0'; return p; }
    return nullptr;
}

// double-conversion's shortest digits (the fallback, and the tests' second opinion).
extern "C" int sc_dtoa_dc(double v, char *buf)
{
    char *p = special(v, buf);
    if (!p) {
        char d[40] = {0};
        bool sign;
        int len, point;
        double_conversion::DoubleToStringConverter::DoubleToAscii(
            v, double_conversion::DoubleToStringConverter::SHORTEST, 0, d, 20, &sign, &len,
            &point);
        p = buf;
        if (sign) *p++ = '-';
        p = layout(p, d, len, point);
    }
    *p = '\0';
    return (int)(p - buf);
}

#ifdef SC_DRAGONBOX
static const char D2[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";
// 8 decimal digits of n < 10^8, two at a time: y = n * ceil(2^57 / 10^6) holds n / 10^6
// in 57.57 fixed point (within 10^8 units of 2^-57: under the 2^57 / 10^6 a digit
// step needs), each step takes the integer part and multiplies the fraction by 100
// (James Anhalt's method; checked for every n < 10^8 when it was written).
static inline void w8(char *p, uint32_t n)
{
    const uint64_t m = (1ull << 57) - 1;
    uint64_t y = (uint64_t)n * 144115188076ull;
    std::memcpy(p, D2 + 2 * (y >> 57), 2);
    y = (y & m) * 100;
    std::memcpy(p + 2, D2 + 2 * (y >> 57), 2);
    y = (y & m) * 100;
    std::memcpy(p + 4, D2 + 2 * (y >> 57), 2);
    y = (y & m) * 100;
    std::memcpy(p + 6, D2 + 2 * (y >> 57), 2);
}
static const uint64_t P10[18] = {
    1ull, 10ull, 100ull, 1000ull, 10000ull, 100000ull, 1000000ull, 10000000ull,
    100000000ull, 1000000000ull, 10000000000ull, 100000000000ull, 1000000000000ull,
    10000000000000ull, 100000000000000ull, 1000000000000000ull, 10000000000000000ull,
    100000000000000000ull};
#endif

// Writes the digits of v at buf (room for 32 bytes and SC_DTOA_SLACK more),
// NUL-terminated; returns the length.
extern "C" int sc_dtoa(double v, char *buf)
{
#ifdef SC_DRAGONBOX
    uint64_t u;
    std::memcpy(&u, &v, 8);
    char *p;
    // zeros, infinities and nan aside; no branch on the sign (x, y, dx, dy are as
    // often negative as not) nor on the digit count
    if ((u << 1) - 1 >= (0x7ffull << 53) - 1) {
        p = special(v, buf);
    } else {
        buf[0] = '-';
        p = buf + (u >> 63);
        auto r = fmt::detail::dragonbox::to_decimal(std::fabs(v));
        uint64_t n = r.significand;              // < 10^17, no trailing zeros
        char t[40];
        uint64_t hi = n / 100000000u;
        t[0] = (char)('0' + hi / 100000000u);
        w8(t + 1, (uint32_t)(hi % 100000000u));
        w8(t + 9, (uint32_t)(n - hi * 100000000u));
        int g = (64 - __builtin_clzll(n)) * 1233 >> 12;   // floor(log10(2^bits))
        int len = g + (n >= P10[g]);
        p = layout(p, t + 17 - len, len, len + r.exponent);
    }
    *p = '\0';
    return (int)(p - buf);
#else
    return sc_dtoa_dc(v, buf);
#endif
}

extern "C" const char *sc_dtoa_name(void)
{
#ifdef SC_DRAGONBOX
    return "Dragonbox (libfmt)";
#else
    return "double-conversion";
#endif
}
