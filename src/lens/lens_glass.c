/* lens_glass.c -- how the lens readers turn a glass name into a catalogue entry:
 * the catalogues a file selects, the built-in catalogue, the AGF catalogues, and the
 * former names (BK7 -> N-BK7), each choice that is not plain said in a note. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include "lens_text.h"
#include "paraxial/paraxial.h"

#define MAXHIT 16

/* The rank of catalogue c in the lens's selection (0 first), or -1 when it is not
 * selected. */
static int rank(const ln_lens *l, const char *c)
{
    for (int i = 0; i < l->ncat; i++)
        if (!strcasecmp(l->catalogs[i], c)) return i;
    return -1;
}

/* The entry taken for name among hits (h of them): the first selected catalogue's
 * when the lens selects any that holds it, else the first (built-in, then AGF in
 * order). */
static int choose(const ln_lens *l, const px_glass_rec **hit, int h)
{
    int best = -1, br = 1 << 30;
    for (int i = 0; i < h && i < MAXHIT; i++) {
        int r = rank(l, hit[i]->catalog ? hit[i]->catalog : "LENSMAT");
        if (r >= 0 && r < br) { br = r; best = i; }
    }
    return best >= 0 ? best : 0;
}

static void store(const px_glass_rec *g, char *out)
{
    const char *c = g->catalog ? g->catalog : "LENSMAT";
    if (!strcmp(c, "LENSMAT")) snprintf(out, LN_NAME_MAX, "%s", g->name);
    else snprintf(out, LN_NAME_MAX, "%s:%s", c, g->name);
}

static int lookup(const ln_lens *l, const char *name, char *out, ln_notes *notes,
                  const char *src, long line, const char *asked)
{
    const px_glass_rec *hit[MAXHIT];
    int h, k;
    if (strchr(name, ':')) {                       /* CATALOG:NAME as written */
        const px_glass_rec *g = px_glass_find(name);
        if (!g) return 0;
        store(g, out);
        return 1;
    }
    h = px_glass_find_all(name, hit, MAXHIT);
    if (h == 0) return 0;
    k = choose(l, hit, h);
    store(hit[k], out);
    if (h > 1) {
        char list[512] = "";
        size_t n = 0;
        for (int i = 0; i < h && i < MAXHIT; i++)
            n += (size_t)snprintf(list + n, n < sizeof list ? sizeof list - n : 0, "%s%s",
                                  i ? ", " : "", hit[i]->catalog ? hit[i]->catalog : "LENSMAT");
        /* how much the choice matters: the largest index difference at F, d, C */
        double dmax = 0;
        for (int i = 0; i < h && i < MAXHIT; i++)
            for (int w = 0; w < 3; w++) {
                double lw = w == 0 ? PX_LAMBDA_F : w == 1 ? PX_LAMBDA_D : PX_LAMBDA_C;
                double a = px_glass_formula(hit[k], lw), b = px_glass_formula(hit[i], lw);
                if (fabs(a - b) > dmax || isnan(a - b)) dmax = isnan(a - b) ? INFINITY : fabs(a - b);
            }
        ln_note(notes, src, line, "glass %s is in %d catalogues (%s): %s's is taken (%s; "
                "their indices at F, d, C differ by up to %.1e)",
                asked, h, list, hit[k]->catalog ? hit[k]->catalog : "LENSMAT",
                l->ncat && rank(l, hit[k]->catalog ? hit[k]->catalog : "LENSMAT") >= 0
                ? "the first selected catalogue that has it"
                : "the built-in catalogue first, then the AGF catalogues in the order read",
                dmax);
    }
    return 1;
}

int ln_glass_lookup(const ln_lens *l, const char *name, char *out, ln_notes *notes,
                    const char *src, long line)
{
    const char *why = NULL, *now;
    static int said;                  /* catalogue files that failed: said once a process */
    if (!said && *px_glass_cat_notes()) {
        const char *p = px_glass_cat_notes();
        said = 1;
        while (*p) {
            const char *nl = strchr(p, '\n');
            int k = nl ? (int)(nl - p) : (int)strlen(p);
            ln_note(notes, src, 0, "glass catalogue skipped: %.*s", k, p);
            p += k + (nl != NULL);
        }
    }
    if (lookup(l, name, out, notes, src, line, name)) return 1;
    if ((now = px_glass_former(name, &why)) && lookup(l, now, out, notes, src, line, now)) {
        ln_note(notes, src, line, "glass %s is a former name: read as %s, %s", name, out,
                why);
        return 1;
    }
    return 0;
}
