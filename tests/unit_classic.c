/* unit_classic.c -- unit tests of the answer lexer and of the paraxial core the
 * classic dialogue uses: number syntax, the record echo's round trip, and the
 * determinant of long products (1000-surface periodic relay; 10 000-surface random
 * chain whose entries grow past 1e50). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "unit.h"
#include "dialogue/lex.h"
#include "paraxial/paraxial.h"

static void test_numbers(void)
{
    static const char *good[] = {"0", "-3", "+2.5", "1.", ".5", "1e3", "-1.5E-7", "25"};
    static const char *bad[] = {"abc", "1.2.3", "1,5", "0x10", "1e", ".", "-", "e5",
                                "1e+", "12abc", "--1", ""};
    double v;
    for (size_t i = 0; i < sizeof good / sizeof *good; i++)
        CHECK(lm_parse_number(good[i], &v) == LM_NUM_OK && v == strtod(good[i], NULL),
              "number '%s' accepted", good[i]);
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        CHECK(lm_parse_number(bad[i], &v) == LM_NUM_SYNTAX, "'%s' rejected", bad[i]);
    CHECK(lm_parse_number("nan", &v) == LM_NUM_NAN, "nan rejected as nan");
    CHECK(lm_parse_number("-NaN", &v) == LM_NUM_NAN, "-NaN rejected as nan");
    CHECK(lm_parse_number("inf", &v) == LM_NUM_PLANE && v == INFINITY, "inf is a plane");
    CHECK(lm_parse_number("Plane", &v) == LM_NUM_PLANE, "Plane is a plane");
    CHECK(lm_parse_number("-inf", &v) == LM_NUM_PLANE && v == -INFINITY, "-inf plane");
    CHECK(lm_parse_number("1e400", &v) == LM_NUM_RANGE, "1e400 out of range");
    CHECK(lm_parse_number("2e30", &v) == LM_NUM_RANGE, "2e30 beyond the limit");
    CHECK(lm_parse_number("1e-400", &v) == LM_NUM_OK && v == 0.0, "1e-400 underflows to 0");
}

static void test_yn_and_tokens(void)
{
    const char *line = lm_line_start("input: 1.5  y\n"), *cur = line;
    char tok[LM_TOKEN_MAX];
    CHECK(lm_parse_yn("Y") == 'y' && lm_parse_yn("yes") == 'y' && lm_parse_yn("NO") == 'n',
          "y/yes/NO");
    CHECK(lm_parse_yn("maybe") == 0 && lm_parse_yn("ye") == 0, "maybe, ye rejected");
    CHECK(lm_next_token(&cur, tok, sizeof tok) == 3 && !strcmp(tok, "1.5"), "token 1.5");
    CHECK(lm_next_token(&cur, tok, sizeof tok) == 1 && !strcmp(tok, "y"), "token y");
    CHECK(lm_next_token(&cur, tok, sizeof tok) == 0, "end of line");
    cur = "  input:x";
    cur = lm_line_start(cur);
    CHECK(lm_next_token(&cur, tok, sizeof tok) == 1 && !strcmp(tok, "x"),
          "input: prefix skipped even without a blank");
}

/* The echo is the original's %g whenever that is exact, else 17 digits. */
static void test_echo(void)
{
    char buf[64];
    lm_format_echo(1.5, buf, sizeof buf);
    CHECK(!strcmp(buf, "1.5"), "echo 1.5 as %%g");
    lm_format_echo(-40.326, buf, sizeof buf);
    CHECK(!strcmp(buf, "-40.326"), "echo -40.326 as %%g");
    srand(42);
    int exact = 1;
    for (int i = 0; i < 100000; i++) {
        double v = (rand() / (double)RAND_MAX - 0.5) * pow(10, rand() % 40 - 20);
        lm_format_echo(v, buf, sizeof buf);
        if (strtod(buf, NULL) != v) exact = 0;
    }
    CHECK(exact, "echo round-trips 100000 random doubles");
}

/* 500 thin lenses f = 37.3 spaced 2f: a relay of period 4, entries bounded. */
static void test_relay_det(void)
{
    px_system s;
    double z = 0, maxe = 0;
    px_system_init(&s, 1.0);
    for (int i = 0; i < 500; i++) {
        px_system_translate(&s, z);
        px_system_refract(&s, 37.3, 1.5);    /* (1-1.5)/37.3 */
        px_system_refract(&s, -37.3, 1.0);   /* thin: same z */
        z += 74.6;
        maxe = fmax(maxe, fmax(fmax(fabs(s.m.a), fabs(s.m.b)), fmax(fabs(s.m.c), fabs(s.m.d))));
    }
    CHECK(s.nsurf == 1000, "1000 surfaces");
    CHECK(maxe < 1e3, "relay entries stay bounded (max %g)", maxe);
    CHECK(fabs(px_det(s.m) - 1) < 1e-12, "1000-surface relay |det-1| = %.3g < 1e-12",
          fabs(px_det(s.m) - 1));
    CHECK(!px_is_afocal(&s) || fabs(s.m.c) < 1e-12, "relay afocal decision consistent");
    px_system_free(&s);
}

/* Random chain: entries grow without bound; the determinant can only be judged
 * relative to |AD| + |BC|. */
static void test_random_chain_det(void)
{
    px_system s;
    double z = 0, n = 1.0;
    srand(7);
    px_system_init(&s, 1.0);
    for (int i = 0; i < 10000; i++) {
        double r = (50 + 450 * (rand() / (double)RAND_MAX)) * (rand() % 2 ? 1 : -1);
        double n2 = 1 + rand() / (double)RAND_MAX;
        px_system_translate(&s, z);
        px_system_refract(&s, r, n2);
        n = n2;
        z += 0.1 + 2 * (rand() / (double)RAND_MAX);
    }
    (void)n;
    double scale = fabs(s.m.a * s.m.d) + fabs(s.m.b * s.m.c);
    double rel = fabs(px_det_accurate(s.m) - 1) / scale;
    CHECK(scale > 1e20, "random chain entries grow (|AD|+|BC| = %.3g)", scale);
    CHECK(rel < 1e4 * DBL_EPSILON, "random chain |det-1|/(|AD|+|BC|) = %.3g at rounding level",
          rel);
    px_system_free(&s);
}

int main(void)
{
    test_numbers();
    test_yn_and_tokens();
    test_echo();
    test_relay_det();
    test_random_chain_det();
    return unit_failed();
}
