/* t_drift.c -- fixation drift during a scan (issue 19 item 6, doc/scan-time.md): the
 * topography pipeline's whole measurement (topo_api.measure) on the simulated chip
 * with golden/rig/example.rig, exposed on the fly, while the true eye moves 10 or
 * 50 um sideways (slowly over the scan, or in one saccade at its middle).  What the
 * drift does to R, mean K, cylinder and the maps' indices (against the same scan
 * without drift), and whether the fit's drift test (a pose per time segment) flags
 * it: the injected displacement is the reference, not anything the detector computed.
 * Scans without drift (a toric eye, a sphere, a cone) must not be flagged.  Prints
 * PASS/FAIL lines and BENCH lines (scripts/bench_scan.sh); exit 1 on a FAIL.
 * Usage: t_drift [POINTS] (default 600). */
#include <math.h>
#define M_PI 3.14159265358979323846
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "topo/topo.h"

static const rig_api *rg;
static const cornea_api *cn;
static const topo_api *tp;
static rg_rig rig;
static int fails;

static void check(int ok, const char *what)
{
    printf("%s %s\n", ok ? "PASS" : "FAIL", what);
    if (!ok) fails++;
}

typedef struct out {
    int ok, flagged;
    double R, Km, cyl, kmax, ck, range, p, sim_s, jR, jKm, jcyl, jchi, schi;
    int segments;
    double vratio, aratio;      /* the fastest joint speed and acceleration between
                                   consecutive pulses, over the rig file's */
    long pulses;
} out;

/* Independent of the planner: from the motors' positions at each pulse and the
 * machine's clock alone, the mean speed of each joint between consecutive pulses
 * (never above its speed) and the change of those speeds over a pulse (never above
 * its acceleration: the sweep ramps within half of it and turns within the other
 * half, so the sum stays within it). */
typedef struct pk { double t; const tp_point *q; } pk;
static int by_t(const void *a, const void *b)
{
    const pk *x = a, *y = b;
    return x->t < y->t ? -1 : x->t > y->t;
}
static void kinematics(const tp_run *r, out *o)
{
    pk *v = malloc(sizeof *v * (size_t)r->npoints);
    long n = 0;
    if (!v) return;
    for (int k = 0; k < r->npoints; k++)
        if (isfinite(r->pt[k].t_s)) v[n++] = (pk){r->pt[k].t_s, &r->pt[k]};
    qsort(v, (size_t)n, sizeof *v, by_t);
    o->pulses = n;
    double prev[RG_NJOINTS] = {0};
    for (long i = 1; i < n; i++) {
        double dt = v[i].t - v[i - 1].t;
        for (int j = 0; j < RG_NJOINTS; j++) {
            const rg_axis *x = &rig.axis[j];
            double u = x->linear ? 1 : M_PI / 180;
            double sp = (v[i].q->pose.j[j] - v[i - 1].q->pose.j[j]) / u / dt;
            /* (one step of slack: the positions are whole steps) */
            double vr = (fabs(sp) - 1 / x->steps_per / dt) / x->speed;
            if (vr > o->vratio) o->vratio = vr;
            if (i > 1) {
                double dtm = 0.5 * (v[i].t - v[i - 2].t), a = fabs(sp - prev[j]) / dtm;
                if (a / x->accel > o->aratio) o->aratio = a / x->accel;
            }
            prev[j] = sp;
        }
    }
    free(v);
}

/* One scan: eye (R, Q, cyl), a cone of h mm (0: none), the drift. */
static out scan(int npoints, double R, double Q, double cyl, double h, int kind, double amp)
{
    out o;
    char err[512];
    rg_machine *m = NULL;
    rg_open_opts oo = {RG_BACKEND_SIM, NULL, NULL, NULL, 0};
    static rg_geometry g;
    tp_run *r = calloc(1, sizeof *r);
    memset(&o, 0, sizeof o);
    g = rig.geom;
    rg_cornea eye = g.cornea;
    double km = 337.5 / R, at[3] = {g.cornea.trans[0] + 0.1732, g.cornea.trans[1] + 0.1,
                                    g.cornea.trans[2]};
    eye.model = RG_BICONIC;
    eye.R = 337.5 / (km - cyl / 2);
    eye.R2 = 337.5 / (km + cyl / 2);
    eye.Q = eye.Q2 = Q;
    eye.axis = 0;
    eye.zone = 0;
    rg->eye_pose(&eye, 2 * M_PI / 180, 0, 0, at);
    cn_bump cone = {h, 0.8, 0, -1.5};
    r->rg = rg;
    r->cn = cn;
    r->g = &g;
    r->truth = eye;
    r->have_truth = 1;
    cn->params_from_cornea(&eye, g.cornea.trans, 2 * M_PI / 180, 0, &r->truth_p);
    if (h > 0) r->bump = &cone;
    r->pattern = TP_RINGS;
    r->npoints = npoints;
    r->zone = 12 * M_PI / 180;
    r->source = TP_SRC_MODEL;
    r->sigma = 0.04 * 0.014;
    r->cam = (tp_camera){640, 480, 0.014, 3, 1000, 100, 50};
    r->seed = 1;
    r->threads = 2;
    r->expose_ms = 0.02;
    r->model = CN_BICONIC;
    r->check_tol = 1e-3;
    r->rig = &rig;
    r->drift.kind = kind;
    r->drift.amp = amp;
    r->drift.dir = 0;
    r->zf = calloc(1, sizeof *r->zf);
    r->pt = calloc((size_t)npoints, sizeof *r->pt);
    if (!r->zf || !r->pt) goto done;
    if (rg->open(&rig, &oo, &m, err, sizeof err) || rg->home(m, NULL, NULL, err, sizeof err)) {
        printf("# machine: %s\n", err);
        goto done;
    }
    r->m = m;
    if (tp->measure(r, err, sizeof err)) { printf("# measure: %s\n", err); goto done; }
    o.ok = r->fitted && r->sc.on_fly;
    o.R = r->res.par.p[CN_R];
    o.Km = r->res.k.Km;
    o.cyl = r->res.k.cyl;
    o.kmax = r->have_z ? r->kc.kmax : NAN;
    o.ck = r->have_z ? r->kc.ck : NAN;
    o.flagged = r->drift.flagged;
    o.range = r->drift.range;
    o.p = r->drift.p;
    o.segments = r->drift.segments;
    o.sim_s = r->sc.sim_s;
    o.jR = r->drift.joint_fitted ? r->drift.joint.par.p[CN_R] : NAN;
    o.jKm = r->drift.joint_fitted ? r->drift.joint.k.Km : NAN;
    o.jcyl = r->drift.joint_fitted ? r->drift.joint.k.cyl : NAN;
    o.jchi = r->drift.joint_chi2_dof;
    o.schi = r->drift.single_chi2_dof;
    kinematics(r, &o);
done:
    if (m) rg->close(m);
    free(r->zf);
    free(r->pt);
    free(r);
    return o;
}

int main(int argc, char **argv)
{
    char err[512], what[256];
    int n = argc > 1 ? atoi(argv[1]) : 600;
    rg = rig_get_api(RIG_ABI);
    cn = cornea_get_api(CORNEA_ABI);
    tp = topo_get_api(TOPO_ABI);
    if (!rg || !cn || !tp) { puts("FAIL engines"); return 1; }
    if (rg->rig_load("golden/rig/example.rig", &rig, err, sizeof err)) {
        printf("FAIL rig: %s\n", err);
        return 1;
    }
    /* no drift: the reference scans, and no false flag (toric, sphere, cone) */
    out base = scan(n, 7.8, -0.26, 0.75, 0, TP_DRIFT_NONE, 0);
    out sph = scan(n, 7.8, 0, 0, 0, TP_DRIFT_NONE, 0);
    out cone = scan(n, 7.8, -0.26, 0, 0.01, TP_DRIFT_NONE, 0);
    check(base.ok && sph.ok && cone.ok, "drift: the three scans without drift ran on the fly and fitted");
    snprintf(what, sizeof what, "drift: no drift, not flagged (toric p %.2g, sphere p %.2g, "
             "cone p %.2g; spreads %.2f, %.2f, %.2f um; the cone's chi2/dof %.3g, with a pose "
             "per segment %.3g)", base.p, sph.p, cone.p, base.range * 1e3, sph.range * 1e3,
             cone.range * 1e3, cone.schi, cone.jchi);
    check(!base.flagged && !sph.flagged && !cone.flagged &&
          base.segments == (n / 20 < TP_DRIFT_SEGMENTS ? n / 20 : TP_DRIFT_SEGMENTS),
          what);
    printf("BENCH topo_drift_false_flags %d count\n", base.flagged + sph.flagged + cone.flagged);
    snprintf(what, sizeof what, "sweep: %ld pulses; between pulses each joint within its "
             "speed (%.3f of it) and acceleration (%.3f of it)", base.pulses, base.vratio,
             base.aratio);
    /* (the acceleration from mean speeds over whole legs: it overstates the sweep's
       turns, whose jump is bounded at the junction, by up to half) */
    check(base.pulses == n && base.vratio <= 1.0001 && base.aratio <= 1.5, what);
    static const struct { const char *name; int kind; double amp; } cs[] = {
        {"lin10", TP_DRIFT_LINEAR, 0.010}, {"lin50", TP_DRIFT_LINEAR, 0.050},
        {"sac10", TP_DRIFT_SACCADE, 0.010}, {"sac50", TP_DRIFT_SACCADE, 0.050}};
    for (int i = 0; i < 4; i++) {
        out d = scan(n, 7.8, -0.26, 0.75, 0, cs[i].kind, cs[i].amp);
        double dR = (d.R - base.R) * 1e3, dK = d.Km - base.Km, dc = d.cyl - base.cyl,
               dkmax = d.kmax - base.kmax, dck = d.ck - base.ck;
        double jR = (d.jR - base.R) * 1e3, jK = d.jKm - base.Km, jc = d.jcyl - base.cyl;
        printf("# %s: %g um, %.3g s: R %+.3f um, mean K %+.4f D, cylinder %+.4f D, Kmax %+.3f D, "
               "central K %+.3f D; test p %.2g, segments spread %.2f um, flagged %d; with a "
               "pose per segment: R %+.3f um, mean K %+.4f D, cylinder %+.4f D (chi2/dof %.3g, "
               "one pose %.3g)\n",
               cs[i].name, cs[i].amp * 1e3, d.sim_s, dR, dK, dc, dkmax, dck, d.p, d.range * 1e3,
               d.flagged, jR, jK, jc, d.jchi, d.schi);
        printf("BENCH topo_drift_%s_corrected_R_um %.3f um\n", cs[i].name, fabs(jR));
        printf("BENCH topo_drift_%s_corrected_K_D %.4f D\n", cs[i].name, fabs(jK));
        printf("BENCH topo_drift_%s_R_um %.3f um\n", cs[i].name, fabs(dR));
        printf("BENCH topo_drift_%s_K_D %.4f D\n", cs[i].name, fabs(dK));
        printf("BENCH topo_drift_%s_cyl_D %.4f D\n", cs[i].name, fabs(dc));
        printf("BENCH topo_drift_%s_kmax_D %.3f D\n", cs[i].name, fabs(dkmax));
        printf("BENCH topo_drift_%s_seen_um %.2f um\n", cs[i].name, d.range * 1e3);
        printf("BENCH topo_drift_%s_flagged %d bool\n", cs[i].name, d.flagged);
        snprintf(what, sizeof what, "drift: %s (%g um) flagged", cs[i].name, cs[i].amp * 1e3);
        check(d.ok && d.flagged, what);
        /* the segments' spread against the injected displacement: a saccade puts the
           segments at 0 and amp; a linear drift's segment means span (S - 1) / S of it */
        double want = cs[i].kind == TP_DRIFT_SACCADE ? cs[i].amp
                      : d.segments > 1 ? cs[i].amp * (d.segments - 1) / d.segments : NAN;
        snprintf(what, sizeof what, "drift: %s: the segments' spread %.2f um within 30 %% of "
                 "the %.2f um injected", cs[i].name, d.range * 1e3, want * 1e3);
        check(d.ok && fabs(d.range - want) < 0.3 * want, what);
    }
    return fails ? 1 : 0;
}
