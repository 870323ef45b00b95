/* dtoa_check.c -- the hit writer's digits (src/trace/scene_dtoa.cpp) for tests/t_71_hits.sh:
 * prints "BITS DIGITS DC-DIGITS" for each double, DIGITS what the CSV writes (Dragonbox)
 * and DC-DIGITS double-conversion's through the same layout.  The doubles: the bit
 * patterns (16 hex digits) given on stdin, then N pseudo-random bit patterns (argv[1],
 * xorshift64 from argv[2]) and N random decimals of 1-17 digits with exponents across the
 * layout's range (where shortest strings are short and the layout switches).  The test
 * checks them with Python's repr (David Gay's algorithm: an independent shortest). */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int sc_dtoa(double v, char *buf);
int sc_dtoa_dc(double v, char *buf);

static void show(uint64_t u)
{
    double v;
    char a[64], b[64];
    memcpy(&v, &u, 8);
    int la = sc_dtoa(v, a), lb = sc_dtoa_dc(v, b);
    if (la != (int)strlen(a) || lb != (int)strlen(b)) printf("LENGTH ");
    printf("%016" PRIx64 " %s %s\n", u, a, b);
}

int main(int argc, char **argv)
{
    long n = argc > 1 ? atol(argv[1]) : 0;
    uint64_t x = argc > 2 ? strtoull(argv[2], NULL, 0) : 88172645463325252ull;
    char line[64];
    while (fgets(line, sizeof line, stdin)) show(strtoull(line, NULL, 16));
    for (long i = 0; i < 2 * n; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        if (i < n) { show(x); continue; }
        char s[48];
        double v;
        uint64_t u;
        int digits = 1 + (int)(x % 17), e = (int)((x >> 8) % 50) - 25;
        uint64_t p10 = 1;
        for (int k = 0; k < digits; k++) p10 *= 10;
        snprintf(s, sizeof s, "%s%" PRIu64 "e%d", x >> 63 ? "-" : "", (x >> 9) % p10, e);
        v = strtod(s, NULL);
        memcpy(&u, &v, 8);
        show(u);
    }
    return 0;
}
