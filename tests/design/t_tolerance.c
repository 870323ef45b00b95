/* t_tolerance.c -- tolerancing against the test's own models.
 *  - Sensitivities: each radius, thickness and index of Sasian's triplet (indices at
 *    d as plain numbers) moved by its tolerance; the engine's EFL and back focus
 *    against this file's own y-nu trace of the moved lens (dsu_yn), to 1e-9.
 *  - Monte Carlo: 4000 lenses, uniform draws; the EFL's sample sd against the linear
 *    prediction sqrt(sum (dEFL/dp)^2 delta^2/3) (within 5 %: the sd of 4000 draws
 *    has a 1.1 % standard error, the second order adds a little); the mean EFL
 *    against the nominal.
 *  - Reproducibility: lens k is the same alone, after others and in another order.
 *  - The back-focus compensator: the refocused RMS is no larger than without, and
 *    the compensator of the nominal lens is the quadratic's minimum (the RMS at
 *    dz +- 1e-3 mm, image plane moved in the file, is larger). */
#include "dsu.h"

static const char *lens_text =
    "thickness\nwavelengths d\nepd 12.5\n%s"
    "23.713     4.831    1.691002\n"
    "7331.288   5.86     air\n"
    "-24.456    0.975    1.672707 stop\n"
    "21.896     4.822    air\n"
    "86.759     3.127    1.691002\n"
    "-20.4942   %.10g  air\n"
    "tol r all 0.2%%\ntol t all 0.05\ntol n all 0.0005\n";

static const double R[6] = {23.713, 7331.288, -24.456, 21.896, 86.759, -20.4942};
static const double T[6] = {4.831, 5.86, 0.975, 4.822, 3.127, 41.2365};
static const double N[6] = {1.691002, 1, 1.672707, 1, 1.691002, 1};

static void own(int kind, int surf, double v, double *efl, double *bfd)
{
    double c[6], t[6], n[6];
    for (int i = 0; i < 6; i++) { c[i] = 1 / R[i]; t[i] = T[i]; n[i] = N[i]; }
    if (kind == 0) c[surf] = 1 / (R[surf] + v);
    if (kind == 1) t[surf] += v;
    if (kind == 2) n[surf] += v;
    dsu_yn(6, c, t, n, efl, bfd);
}

int main(void)
{
    char text[4096], err[DS_ERR_MAX];
    dsu_init();
    snprintf(text, sizeof text, lens_text, "", 41.2365);
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "triplet read: %s", p ? "" : err);
    if (!p) return 1;
    ds_tol_opts o;
    ds->tol_defaults(p, &o);
    int nt = ds->ntol(p);
    CHECK(nt == 6 + 5 + 3, "14 tolerances: 6 radii, 5 thicknesses (not the image distance), "
          "3 glasses (got %d)", nt);
    double worst = 0, var = 0;
    for (int i = 0; i < nt; i++) {
        ds_tol_info ti;
        ds_crit a, b;
        ds->tol_info(p, i, &ti);
        int kind = ti.name[0] == 'r' ? 0 : ti.name[0] == 't' ? 1 : 2, s = atoi(ti.name + 2) - 1;
        ds->tol_one(p, &o, i, -1, &a);
        ds->tol_one(p, &o, i, 1, &b);
        double ea, eb, ba, bb;
        own(kind, s, -ti.delta, &ea, &ba);
        own(kind, s, ti.delta, &eb, &bb);
        double e = fmax(fmax(fabs(a.efl - ea), fabs(b.efl - eb)), fmax(fabs(a.bfd - ba), fabs(b.bfd - bb)));
        worst = fmax(worst, e / 50);
        var += pow((eb - ea) / 2, 2) / 3;
    }
    CHECK(worst < 1e-9, "sensitivities: efl and bfd at +-delta of all %d tolerances equal the "
          "test's own y-nu trace to %.2g relative", nt, worst);
    /* Monte Carlo against the linear prediction */
    double s = 0, s2 = 0, nom;
    ds_crit c0;
    ds->tol_nominal(p, &o, &c0);
    nom = c0.efl;
    int M = 4000;
    for (int k = 1; k <= M; k++) {
        ds_crit c;
        ds->tol_mc(p, &o, 7, k, &c);
        s += c.efl;
        s2 += c.efl * c.efl;
    }
    double m = s / M, sd = sqrt((s2 - M * m * m) / (M - 1)), pred = sqrt(var);
    CHECK(fabs(sd / pred - 1) < 0.05, "Monte Carlo (%d lenses, uniform): efl sd %.6g, linear "
          "prediction %.6g (ratio %.4f)", M, sd, pred, sd / pred);
    CHECK(fabs(m - nom) < 4 * pred / sqrt(M) + 1e-3 * pred, "Monte Carlo: mean efl %.6g, nominal %.6g", m, nom);
    ds_crit x1, x2, x3;
    ds->tol_mc(p, &o, 7, 1234, &x1);
    ds->tol_mc(p, &o, 7, 99, &x2);
    ds->tol_mc(p, &o, 7, 1234, &x3);
    CHECK(x1.efl == x3.efl && x1.bfd == x3.bfd && x1.efl != x2.efl,
          "lens 1234 of seed 7 is the same whenever it is drawn (%.12g)", x1.efl);
    ds->free(p);

    /* the compensator on a lens with fields (real rays) */
    snprintf(text, sizeof text, lens_text, "field angle 0 14.14 20\n", 41.2365);
    p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "triplet with fields read: %s", p ? "" : err);
    if (!p) return 1;
    ds_crit on, off;
    ds->tol_defaults(p, &o);
    o.compensate = 1;
    ds->tol_nominal(p, &o, &on);
    o.compensate = 0;
    ds->tol_nominal(p, &o, &off);
    CHECK(on.ok && off.ok && on.rms <= off.rms, "refocused RMS %.6g um <= %.6g um as built "
          "(refocus %.5g mm)", on.rms * 1e3, off.rms * 1e3, on.focus);
    ds->free(p);
    double dz[2] = {-1e-3, 1e-3};
    for (int j = 0; j < 2; j++) {
        ds_crit q;
        snprintf(text, sizeof text, lens_text, "field angle 0 14.14 20\n", 41.2365 + on.focus + dz[j]);
        p = dsu_problem(text, err, sizeof err);
        if (!p) break;
        o.compensate = 0;
        ds->tol_nominal(p, &o, &q);
        CHECK(q.rms > on.rms, "image plane at the compensator's best %+g mm: RMS %.9g um > %.9g um",
              dz[j], q.rms * 1e3, on.rms * 1e3);
        ds->free(p);
    }
    return unit_failed();
}
