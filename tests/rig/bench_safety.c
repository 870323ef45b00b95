/* bench_safety.c -- the rig's safety figures on the simulated chip (doc/rig-safety.md):
 *   BENCH rig_interlock_motion_stop_ms  simulated time from the interlock opening
 *       mid-move to the last STEP edge after it (0 when none came after), the worst of
 *       200 openings spread over one control step and over the move (target <= 1);
 *       baseline in the same run: the control step itself, the most a controller
 *       that reads the interlock once per step can take;
 *   BENCH rig_dose_mpe_fraction  the example scan's dose (golden/rig/example.rig, the
 *       40 points of 10 ms of tests/t_86's scan) as a fraction of the MPE it names
 *       (IEC 60825-1:2014 Table A.1), and the same scan's fraction at 1 mW.
 * argv[1]: golden/rig/example.rig. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "rig/rig.h"
#include "unit.h"

int main(int argc, char **argv)
{
    const rig_api *rg = rig_get_api(RIG_ABI);
    char *ex0 = unit_slurp(argc > 1 ? argv[1] : "golden/rig/example.rig"), err[RG_ERRMAX];
    static char text[1 << 20], ex[1 << 16];
    char dir[] = "/tmp/bench_safety.XXXXXX", logp[600];
    double worst = 0, homed_at = -1;
    long t0[RG_NJOINTS] = {0};
    int runs = 0;
    rg_rig rig;
    if (ex0) snprintf(ex, sizeof ex, "%s", ex0);
    if (!rg || !rg->dose_plan || !ex0 || !mkdtemp(dir)) { fprintf(stderr, "bench_safety: setup\n"); return 1; }
    snprintf(logp, sizeof logp, "%s/b.log", dir);
    /* the time homing ends, to place the openings in the move after it */
    {
        rg_open_opts o = {RG_BACKEND_SIM, NULL, NULL, NULL, 0};
        rg_machine *m;
        if (rg->rig_parse(ex, strlen(ex), "example.rig", &rig, err, sizeof err) ||
            rg->open(&rig, &o, &m, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 1; }
        o.sim_log = logp;
        rg->close(m);
        if (rg->open(&rig, &o, &m, err, sizeof err) || rg->home(m, NULL, NULL, err, sizeof err)) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        rg->position(m, t0, NULL);
        rg->close(m);
        {
            char *log = unit_slurp(logp), *p = log ? strstr(log, " homed") : NULL;
            while (p && p > log && p[-1] != '\n') p--;
            if (p) homed_at = atof(p);
        }
    }
    /* the move: m1a over most of its travel from home (a trapezoid of the axis's speed
       and acceleration), its duration T from them, so the openings fall in it whatever
       the rig's motors (the example's were 1.1 s for 2000 steps, now 0.1 s) */
    const rg_axis *ax = &rig.axis[RG_J_M1A];
    long nsteps = lround(0.9 * (ax->max * ax->steps_per - t0[RG_J_M1A]));
    double V = ax->speed * ax->steps_per, A = ax->accel * ax->steps_per;
    double T = nsteps > V * V / A ? nsteps / V + V / A : 2 * sqrt(nsteps / A);
    double span_ms = (T * 1e3 - 60) / 200, tick_ms = rig.tick_us / 1e3;
    for (int k = 0; k < 200 && homed_at > 0; k++) {
        /* the move starts after homing and its settle: openings from 50 ms into it to
         * 10 ms before its end, each at another phase of the control step */
        double at_ms = (homed_at + rig.settle_ms / 1e3) * 1e3 + 50 + k * span_ms +
                       k * tick_ms / 200 + 0.0013;
        rg_open_opts o = {RG_BACKEND_SIM, NULL, logp, NULL, 0};
        rg_machine *m;
        long t[RG_NJOINTS];
        char *log, *a, *f;
        snprintf(text, sizeof text, "%s\nsim_interlock_open_ms %.6f\n", ex, at_ms);
        if (rg->rig_parse(text, strlen(text), "b.rig", &rig, err, sizeof err) ||
            rg->open(&rig, &o, &m, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 1; }
        rg->home(m, NULL, NULL, err, sizeof err);
        rg->position(m, t, NULL);
        t[RG_J_M1A] += nsteps;
        rg->move_steps(m, t, NULL, NULL, err, sizeof err);
        rg->close(m);
        log = unit_slurp(logp);
        a = log ? strstr(log, "interlock open\n") : NULL;
        f = log ? strstr(log, "FAULT latched") : NULL;
        if (a && f && !strstr(log, "VIOLATION")) {
            char *l = a, *e = strstr(f, "last STEP edge ");
            double open, edge;
            while (l > log && l[-1] != '\n') l--;
            open = atof(l);
            edge = e ? atof(e + 15) : open;
            if (edge - open > worst) worst = edge - open;
            runs++;
        } else {
            fprintf(stderr, "bench_safety: opening %d: no fault or a violation\n", k);
            return 1;
        }
    }
    printf("# interlock: %d openings mid-move, simulated chip, control step %g us\n", runs,
           rig.tick_us);
    printf("BENCH rig_interlock_motion_stop_ms %.4f ms\n", worst * 1e3);
    printf("BENCH rig_interlock_motion_stop_baseline_ms %.4f ms\n", rig.tick_us / 1e3);
    {
        rg_dose d;
        int rc;
        rg->rig_parse(ex, strlen(ex), "example.rig", &rig, err, sizeof err);
        rc = rg->dose_rig(&rig, 10, 40, &d, err, sizeof err);
        printf("# dose: example rig %g mW, %g nm, %g mm; 40 x 10 ms: %.4g J/m^2 of %.4g "
               "J/m^2 (%s)%s\n", rig.laser_power_mw, rig.wavelength_nm, rig.beam_diameter_mm,
               d.H_total, d.mpe_total, d.limit, rc ? " REFUSED" : "");
        printf("BENCH rig_dose_mpe_fraction %.4f ratio\n", d.fraction);
        rig.laser_power_mw = 1;
        rg->dose_rig(&rig, 10, 40, &d, err, sizeof err);
        printf("BENCH rig_dose_mpe_fraction_1mW %.4f ratio\n", d.fraction);
    }
    unlink(logp);
    rmdir(dir);
    return 0;
}
