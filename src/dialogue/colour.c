/* colour.c -- the --colour dialogue: a prescription by thickness whose media are
 * glasses by name (data/glass.txt), model glasses nd/Vd, media or plain indices; the
 * first-order data at each wavelength asked, then longitudinal and lateral colour
 * (F, d, C) and the glasses' Abbe numbers.  Texts in prompts/colour.txt; the
 * arithmetic in the paraxial engine (src/paraxial/glass.c, colour.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "calcio.h"
#include "dialogues.h"
#include "prompts_colour.h"

#define CO(k) colour_prompts[COLOUR_##k]
#define CL(v) lm_clean(c->io, (v))
#define MAXSURF 64
#define NAME_MAX_ 64

typedef struct colour_session {
    int nwl;
    double wl[PX_COLOUR_MAXWL];
} colour_session;

static int check_wl(void *ctx, const char *w, char *msg, size_t cap)
{
    double *l = ctx;
    if (px_wavelength(w, l) != PX_OK) { snprintf(msg, cap, CO(WL_BAD), w); return 1; }
    return 0;
}

/* A medium must give an index at every wavelength of the session. */
static int check_glass(void *ctx, const char *w, char *msg, size_t cap)
{
    const colour_session *s = ctx;
    for (int i = 0; i < s->nwl; i++) {
        double n;
        int r = px_glass_index(w, s->wl[i], &n);
        const px_glass_rec *g = px_glass_find(w);
        if (r == PX_OK) continue;
        if (r == PX_GLASS_RANGE && g)
            snprintf(msg, cap, CO(RANGE), g->name, g->lmin, g->lmax, s->wl[i]);
        else if (r == PX_GLASS_RANGE)
            snprintf(msg, cap, CO(RANGE_MODEL), w, s->wl[i]);
        else snprintf(msg, cap, CO(NO_GLASS), w);
        return 1;
    }
    return 0;
}

/* "air" here is the catalogue's AIR, index 1, not the classic's 1.000293: say so. */
static int air_note(calc *c, const char *glass)
{
    if (!strcasecmp(glass, "air")) calc_say(c, "%s", CO(AIR_NOTE));
    return LM_GO;
}

static int ask_count(calc *c, const char *q, const char *what, const char *bad, int max,
                     int *k)
{
    return lm_ask_count(c->io, q, q, what, bad, 1, max, k);
}

/* The question with its numbers filled in, for stdout and the record. */
static const char *q1(char *buf, size_t cap, const char *fmt, int a, int b)
{
    snprintf(buf, cap, fmt, a, b);
    return buf;
}

static void report_wavelength(calc *c, const colour_session *s, const char *obj,
                              char (*glass)[NAME_MAX_], int nsurf, int w,
                              const px_first *f)
{
    double n;
    calc_say(c, CO(WL_HEAD), s->wl[w] * 1000);
    calc_say(c, "%s", CO(INDICES));
    px_glass_index(obj, s->wl[w], &n);
    calc_say(c, CO(INDEX), obj, n);
    for (int i = 0; i < nsurf; i++) {
        px_glass_index(glass[i], s->wl[w], &n);
        calc_say(c, CO(INDEX), glass[i], n);
    }
    calc_say(c, " \n");
    if (f->afocal) { calc_say(c, CO(AFOCAL), CL(f->angular.v)); return; }
    calc_say(c, CO(FIRST), CL(f->efl.v), CL(f->ffd.v), CL(f->bfd.v));
    calc_say(c, CO(POINTS), CL(f->z_f1.v), CL(f->z_h1.v), CL(f->z_n1.v), CL(f->z_h2.v),
             CL(f->z_n2.v), CL(f->z_f2.v));
}

/* The optional Seidel sums: pupil semi-diameter and field angle asked. */
static int seidel(calc *c, const px_csurf *surf, int nsurf, const char *obj)
{
    px_seidel q;
    double y, deg;
    int rc, yes;
    lm_mark m;
    if ((rc = calc_yn(c, CO(SEIDEL_Q), CO(SEIDEL_Q_WHAT), &yes)) || !yes) return rc;
    if ((rc = calc_num(c, CO(PUPIL), CO(PUPIL_WHAT), LM_POSITIVE, &y))) return rc;
    for (;;) {
        calc_mark(c, &m);
        if ((rc = calc_num(c, CO(FIELD), CO(FIELD_WHAT), 0, &deg))) return rc;
        if (fabs(deg) <= 60) break;
        if ((rc = calc_reject(c, &m, CO(FIELD_WHAT), CO(FIELD), CO(AGAIN_FIELD), "%s",
                              CO(FIELD_BAD))))
            return rc;
    }
    calc_say(c, CO(SEIDEL_HEAD), y, deg);
    if (px_seidel_run(surf, nsurf, obj, y, tan(deg * 3.14159265358979323846 / 180), &q) != PX_OK) {
        calc_say(c, "%s", CO(SEIDEL_BAD));
        return LM_GO;
    }
    for (int k = 0; k < nsurf; k++) {
        const px_seidel_sums *e = &q.surf[k];
        calc_say(c, CO(SEIDEL_ROW), k + 1, CL(e->s1), CL(e->s2), CL(e->s3), CL(e->s4),
                 CL(e->s5), CL(e->c1), CL(e->c2));
    }
    calc_say(c, CO(SEIDEL_TOTAL), "total", CL(q.total.s1), CL(q.total.s2), CL(q.total.s3),
             CL(q.total.s4), CL(q.total.s5), CL(q.total.c1), CL(q.total.c2));
    if (q.u_last != 0)
        calc_say(c, CO(SEIDEL_DERIVED), CL(q.total.s1 / (2 * q.n_last * q.u_last)), c->uname,
                 CL(-q.total.c1 / (q.n_last * q.u_last * q.u_last)), c->uname);
    return LM_GO;
}

int lm_colour(lm_io *io)
{
    calc cc = {io, PX_MM, "mm"}, *c = &cc;
    colour_session s = {0, {0}};
    char obj[NAME_MAX_], glass[MAXSURF][NAME_MAX_], q[256];
    px_csurf surf[MAXSURF];
    px_colour out, fdc;
    double zlast = 0;
    int rc, nsurf, r;
    if ((rc = calc_unit(c)) ||
        (rc = ask_count(c, CO(NWL), CO(NWL_WHAT), CO(NWL_BAD), PX_COLOUR_MAXWL, &s.nwl)))
        return rc;
    for (int i = 0; i < s.nwl; i++) {
        char w[32];
        q1(q, sizeof q, CO(WL), i + 1, 0);
        if ((rc = lm_ask_word(io, q, q, CO(WL_WHAT), check_wl, &s.wl[i], w, sizeof w)))
            return rc;
    }
    if ((rc = lm_ask_word(io, CO(OBJECT), CO(OBJECT), CO(OBJECT_WHAT), check_glass, &s,
                          obj, sizeof obj)) ||
        (rc = air_note(c, obj)) ||
        (rc = ask_count(c, CO(NSURF), CO(NSURF_WHAT), CO(NSURF_BAD), MAXSURF, &nsurf)))
        return rc;
    for (int i = 0; i < nsurf; i++) {
        double rad;
        surf[i].t = 0;
        q1(q, sizeof q, CO(RADIUS), i + 1, 0);
        if ((rc = calc_num(c, q, CO(RADIUS_WHAT), LM_ALLOW_PLANE, &rad))) return rc;
        surf[i].r = rad;
        q1(q, sizeof q, CO(GLASS), i + 1, 0);
        if ((rc = lm_ask_word(io, q, q, CO(GLASS_WHAT), check_glass, &s, glass[i],
                              sizeof glass[i])) || (rc = air_note(c, glass[i])))
            return rc;
        surf[i].glass = glass[i];
        if (i + 1 < nsurf) {
            q1(q, sizeof q, CO(THICK), i + 1, i + 2);
            if ((rc = calc_num(c, q, CO(THICK_WHAT), LM_NONNEG, &surf[i].t))) return rc;
            zlast += surf[i].t;
        }
    }
    if (lm_stop_requested()) return LM_FAIL;
    calc_say(c, CO(HEAD), zlast, c->uname);
    r = px_colour_run(surf, nsurf, obj, s.wl, s.nwl, &out);
    if (r != PX_OK) return LM_FAIL;     /* every medium was checked at every wavelength */
    for (int w = 0; w < s.nwl; w++) report_wavelength(c, &s, obj, glass, nsurf, w, &out.first[w]);
    calc_say(c, CO(COLOUR_HEAD));
    r = px_colour_fdc(surf, nsurf, obj, &fdc);
    if (r == PX_OK) {
        calc_say(c, CO(LONG), CL(fdc.long_colour), c->uname);
        calc_say(c, CO(LAT), CL(fdc.lat_colour_rel));
    } else {
        char why[160];
        if (r == PX_AT_INFINITY) snprintf(why, sizeof why, "afocal at F, d or C");
        else snprintf(why, sizeof why, "the %s has no index at F, d or C",
                      fdc.bad_surface < 0 ? "object medium" : "glass of a surface");
        calc_say(c, CO(NO_COLOUR), why);
    }
    for (int i = 0; i < nsurf; i++) {
        double vd;
        int seen = 0;
        for (int j = 0; j < i; j++) seen |= !strcmp(glass[j], glass[i]);
        if (seen) continue;
        if (px_glass_abbe(glass[i], &vd) == PX_OK) calc_say(c, CO(ABBE), glass[i], vd);
        else if (px_glass_find(glass[i]) && strcasecmp(glass[i], "air") &&
                 strcasecmp(glass[i], "vacuum"))
            calc_say(c, CO(NO_ABBE), glass[i]);
    }
    if ((rc = seidel(c, surf, nsurf, obj))) return rc;
    return calc_done(c);
}
const char *lm_colour_example(void) { return CO(EXAMPLE); }
