/* polar.c -- the --polar dialogue (seed sections 40, 67-71): Jones vectors through a
 * sequence of polarizers, wave plates, rotators and retarders (the seed's circular
 * polarization of 67.1 among the inputs) with Stokes parameters and the ellipse; the
 * Fresnel amplitude coefficients with the phase of total internal reflection; a
 * thin-film stack's reflectance per wavelength.  Every number from the wave module;
 * texts in prompts/polar.txt. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calcio.h"
#include "dialogues.h"
#include "engine.h"
#include "../wave/wave.h"
#include "prompts_polar.h"

#define P(k) polar_prompts[POLAR_##k]
#define DEG (3.14159265358979323846 / 180)
#define MAXEL 20

static int ask_count(calc *c, const char *q, int lo, int hi, int *v)
{
    return lm_ask_count(c->io, q, q, P(COUNT_WHAT), P(COUNT_BAD), lo, hi, v);
}

static double z0(double v) { return fabs(v) < 1e-15 ? 0.0 : v; }

static void jones_say(calc *c, const char *label, const wave_c e[2])
{
    double ex = hypot(e[0].re, e[0].im), ey = hypot(e[1].re, e[1].im);
    double px = ex > 1e-15 ? atan2(e[0].im, e[0].re) / DEG : 0;
    double py = ey > 1e-15 ? atan2(e[1].im, e[1].re) / DEG : 0;
    double s0 = ex * ex + ey * ey, s1 = ex * ex - ey * ey;
    double s2 = 2 * (e[0].re * e[1].re + e[0].im * e[1].im);
    double s3 = 2 * (e[0].re * e[1].im - e[0].im * e[1].re);
    double az = s0 > 1e-15 ? 0.5 * atan2(z0(s2), z0(s1)) / DEG : 0;
    double ch = s0 > 1e-15 ? 0.5 * asin(fmax(-1, fmin(1, s3 / s0))) / DEG : 0;
    calc_say(c, P(JONES_ROW), label, z0(ex), z0(px), z0(ey), z0(py), z0(s0), z0(az), z0(ch),
             z0(s0), z0(s1), z0(s2), z0(s3));
}

static int jones(calc *c, const wave_api *wv)
{
    static const char *const ins[] = {"h", "v", "d", "a", "l", "r", NULL};
    static const char *const els[] = {"pol", "qwp", "hwp", "rot", "ret", NULL};
    int in = 0, n, rc, kind[MAXEL];
    double ang[MAXEL], ret[MAXEL];
    char q[160];
    if ((rc = calc_choice(c, P(INPUT), P(INPUT_WHAT), ins, &in)) ||
        (rc = ask_count(c, P(NEL), 0, 10, &n)))
        return rc;
    for (int i = 0; i < n; i++) {
        snprintf(q, sizeof q, P(EL), i + 1);
        if ((rc = calc_choice(c, q, P(EL_WHAT), els, &kind[i])) ||
            (rc = calc_num(c, P(ANGLE), P(ANGLE_WHAT), 0, &ang[i])))
            return rc;
        ret[i] = kind[i] == 1 ? 90 : kind[i] == 2 ? 180 : 0;
        if (kind[i] == 4 && (rc = calc_num(c, P(RET), P(RET_WHAT), 0, &ret[i]))) return rc;
    }
    double r2 = sqrt(0.5);
    wave_c e[2];
    switch (in) {
    case 0: e[0] = (wave_c){1, 0}; e[1] = (wave_c){0, 0}; break;
    case 1: e[0] = (wave_c){0, 0}; e[1] = (wave_c){1, 0}; break;
    case 2: e[0] = (wave_c){r2, 0}; e[1] = (wave_c){r2, 0}; break;
    case 3: e[0] = (wave_c){r2, 0}; e[1] = (wave_c){-r2, 0}; break;
    case 4: e[0] = (wave_c){r2, 0}; e[1] = (wave_c){0, r2}; break;
    default: e[0] = (wave_c){r2, 0}; e[1] = (wave_c){0, -r2}; break;
    }
    calc_say(c, "%s", P(JONES_HEAD));
    jones_say(c, P(JONES_IN), e);
    for (int i = 0; i < n; i++) {
        wave_c m[4], o[2];
        char label[64];
        int k = kind[i] == 0 ? 0 : kind[i] == 3 ? 2 : 1;
        if (wv->jones(k, ang[i] * DEG, ret[i] * DEG, m) != WAVE_OK) return LM_FAIL;
        for (int r = 0; r < 2; r++) {
            const wave_c *a = &m[2 * r], *b = &m[2 * r + 1];
            o[r].re = a->re * e[0].re - a->im * e[0].im + b->re * e[1].re - b->im * e[1].im;
            o[r].im = a->re * e[0].im + a->im * e[0].re + b->re * e[1].im + b->im * e[1].re;
        }
        e[0] = o[0];
        e[1] = o[1];
        if (kind[i] == 4) snprintf(label, sizeof label, "%d %s %g, %g:", i + 1, els[kind[i]], ang[i], ret[i]);
        else snprintf(label, sizeof label, "%d %s %g:", i + 1, els[kind[i]], ang[i]);
        jones_say(c, label, e);
    }
    return LM_GO;
}

static int ask_theta(calc *c, double *t)
{
    int rc;
    for (;;) {
        lm_mark m;
        calc_mark(c, &m);
        if ((rc = calc_num(c, P(THETA), P(THETA_WHAT), LM_NONNEG, t))) return rc;
        if (*t <= 90) return LM_GO;
        if ((rc = calc_reject(c, &m, P(THETA_WHAT), P(THETA), P(AGAIN_THETA), "%s", P(THETA_BAD))))
            return rc;
    }
}

static int fresnel(calc *c, const wave_api *wv)
{
    double n1, n2, t;
    int rc;
    if ((rc = calc_index(c, P(N1), P(INDEX_WHAT), &n1)) ||
        (rc = calc_index(c, P(N2), P(INDEX_WHAT), &n2)) || (rc = ask_theta(c, &t)))
        return rc;
    wave_c r[4];
    if (wv->fresnel(n1, n2, t * DEG, r) != WAVE_OK) return LM_FAIL;
    static const char *const names[] = {"rs", "rp", "ts", "tp"};
    calc_say(c, P(FRES_HEAD), n1, n2, t);
    for (int i = 0; i < 4; i++)
        calc_say(c, P(FRES_ROW), names[i], z0(hypot(r[i].re, r[i].im)),
                 z0(hypot(r[i].re, r[i].im) > 1e-15 ? atan2(z0(r[i].im), r[i].re) / DEG : 0));
    double s = n1 / n2 * sin(t * DEG), ci = cos(t * DEG), tir = s > 1;
    double ct = tir ? 0 : sqrt(1 - s * s), f = ci > 0 && !tir ? n2 * ct / (n1 * ci) : 0;
    double Rs = r[0].re * r[0].re + r[0].im * r[0].im, Rp = r[1].re * r[1].re + r[1].im * r[1].im;
    double Ts = f * (r[2].re * r[2].re + r[2].im * r[2].im);
    double Tp = f * (r[3].re * r[3].re + r[3].im * r[3].im);
    char crit[64] = "";
    if (n2 < n1) snprintf(crit, sizeof crit, P(FRES_CRIT), asin(n2 / n1) / DEG);
    calc_say(c, P(FRES_POWER), z0(Rs), z0(Rp), z0(Ts), z0(Tp), atan(n2 / n1) / DEG, crit);
    if (tir) {
        double d = atan2(r[1].im, r[1].re) - atan2(r[0].im, r[0].re);
        double n = n2 / n1, sn = sin(t * DEG);
        double want = -2 * atan(ci * sqrt(sn * sn - n * n) / (sn * sn));
        if (d > 180 * DEG) d -= 360 * DEG;
        if (d < -180 * DEG) d += 360 * DEG;
        calc_say(c, P(FRES_TIR), z0(d / DEG), z0(want / DEG));
    }
    return LM_GO;
}

static int film(calc *c, const wave_api *wv)
{
    double n0, ns, lam, t, n[MAXEL], d[MAXEL];
    int nl, rc;
    char q[128];
    if ((rc = calc_index(c, P(N0), P(INDEX_WHAT), &n0)) ||
        (rc = calc_index(c, P(NS), P(INDEX_WHAT), &ns)) ||
        (rc = calc_num(c, P(DESIGN), P(DESIGN_WHAT), LM_POSITIVE, &lam)) ||
        (rc = ask_count(c, P(NLAYER), 0, MAXEL, &nl)))
        return rc;
    for (int i = 0; i < nl; i++) {
        snprintf(q, sizeof q, P(LINDEX), i + 1);
        if ((rc = calc_index(c, q, P(INDEX_WHAT), &n[i]))) return rc;
        snprintf(q, sizeof q, P(LTHICK), i + 1);
        if ((rc = calc_num(c, q, P(LTHICK_WHAT), LM_NONNEG, &d[i]))) return rc;
        if (d[i] == 0) d[i] = lam / (4 * n[i]);
    }
    if ((rc = ask_theta(c, &t))) return rc;
    calc_say(c, P(FILM_HEAD), n0, ns, nl, nl == 1 ? "" : "s", t);
    for (int i = 0; i < nl; i++)
        calc_say(c, P(FILM_LAYER), i + 1, n[i], d[i], n[i] * d[i] / lam, lam);
    double wl[8] = {lam, 400, 450, 500, 550, 600, 650, 700};
    for (int i = 0; i < 8; i++) {
        double Rs, Rp;
        if (wv->film(n0, n, d, nl, ns, wl[i], t * DEG, &Rs, &Rp) != WAVE_OK) return LM_FAIL;
        calc_say(c, P(FILM_R), wl[i], 100 * Rs, 100 * Rp);
    }
    if (nl == 1 && t == 0 && fabs(n[0] * d[0] - lam / 4) < 1e-12 * lam) {
        double v = (n0 * ns - n[0] * n[0]) / (n0 * ns + n[0] * n[0]);
        calc_say(c, P(FILM_CLOSED), 100 * v * v);
    }
    return LM_GO;
}

int lm_polar(lm_io *io)
{
    static const char *const whats[] = {"jones", "fresnel", "film", NULL};
    calc c = {io, PX_MM, "mm"};
    int w = 0, rc;
    if ((rc = calc_choice(&c, P(WHAT), P(WHAT_WHAT), whats, &w))) return rc;
    wave_get_api_fn get = (wave_get_api_fn)lm_engine_symbol("wave", WAVE_API_SYMBOL);
    const wave_api *wv = get ? get(WAVE_ABI) : NULL;
    if (!wv) return LM_FAIL;
    rc = w == 0 ? jones(&c, wv) : w == 1 ? fresnel(&c, wv) : film(&c, wv);
    return rc == LM_GO ? calc_done(&c) : rc;
}
const char *lm_polar_example(void) { return P(EXAMPLE); }
