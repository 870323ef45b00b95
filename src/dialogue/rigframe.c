/* rigframe.c -- the camera of the --rig dialogue's closed loop: a sensor at the rig's
 * detector point, facing the eye (its normal along apex -> detector, the plane the
 * forward model measures misses in); the traced landing point splatted with the
 * Gaussian beam of section 46 into a noisy frame (shot noise, read noise, 12 bits),
 * the spot located by the imaging engine's Gaussian fit and turned back into rig
 * coordinates.  The imaging engine (OpenCV) is loaded only when a frame is wanted. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "engine.h"
#include "rigframe.h"
#include "../imaging/imaging.h"

#define PLANCK_HC 1.98644586e-25     /* h c, J m */
#define LAMBDA_M 633e-9              /* HeNe: the photon energy and the beam's spread */
#define PI 3.14159265358979323846

int lm_rigcam_load(lm_rigcam *c, char *err, size_t cap)
{
    if (!c->tried) {
        imaging_get_api_fn get =
            (imaging_get_api_fn)lm_engine_symbol("imaging", IMAGING_API_SYMBOL);
        c->tried = 1;
        c->im = get ? get(IMAGING_ABI) : NULL;
        if (c->im && (!c->im->frame || !c->im->frame->synth || !c->im->frame->centroid))
            c->im = NULL;
        if (c->im) c->cz = c->im->frame->centroider_new();
        if (c->im && !c->cz) c->im = NULL;
    }
    if (c->im) return 0;
    snprintf(err, cap, "the imaging engine is not available: no frames");
    return -1;
}

static double dist(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

static void unit(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++) v[k] /= n;
}

/* The sensor's axes: normal n along apex -> detector, x the rig axis least along n
 * made perpendicular, y = n x x. */
static void axes(const rg_geometry *g, double x[3], double y[3])
{
    double n[3], e[3] = {0, 0, 0};
    int k0 = 0;
    for (int k = 0; k < 3; k++) n[k] = g->detector[k] - g->cornea.trans[k];
    unit(n);
    for (int k = 1; k < 3; k++) if (fabs(n[k]) < fabs(n[k0])) k0 = k;
    e[k0] = 1;
    for (int k = 0; k < 3; k++) x[k] = e[k] - (e[0] * n[0] + e[1] * n[1] + e[2] * n[2]) * n[k];
    unit(x);
    y[0] = n[1] * x[2] - n[2] * x[1];
    y[1] = n[2] * x[0] - n[0] * x[2];
    y[2] = n[0] * x[1] - n[1] * x[0];
}

int lm_rigcam_detect(lm_rigcam *c, const rg_rig *r, const rg_beam *b, const double hit[3],
                     double exposure, lm_rigcam_spot *out, char *err, size_t cap)
{
    const im_frame_api *F;
    const rg_geometry *g = &r->geom;
    im_sensor s;
    im_spot_src src;
    im_hit h;
    im_centroid_opt o;
    im_centroid_result res;
    im_spot sp;
    im_frame *f = NULL;
    double path, wz, wpx, theta, photons;
    int rc;
    if (lm_rigcam_load(c, err, cap)) return -1;
    F = c->im->frame;
    memset(&s, 0, sizeof s);
    s.width = s.height = r->cam_pixels;
    s.pitch = r->cam_pitch;
    memcpy(s.origin, g->detector, sizeof s.origin);
    axes(g, s.xdir, s.ydir);
    s.bits = 12;
    s.exposure = exposure;
    s.qe = 1;
    s.gain = 5;                  /* electrons per count: 20 000 e- fill 4 000 counts */
    s.full_well = 20000;
    s.bias = 100;
    s.read_noise = r->cam_read_noise;
    s.shot_noise = 1;
    s.wavelength = LAMBDA_M;
    /* path from the laser's waist: laser -> m1 -> m2 -> cornea -> detector */
    path = dist(g->laser_at, b->h1) + dist(b->h1, b->h2) + dist(b->h2, b->spot) +
           dist(b->spot, hit);
    theta = LAMBDA_M * 1e3 / (PI * r->beam_waist);
    wz = sqrt(r->beam_waist * r->beam_waist + theta * path * theta * path);
    wpx = wz / s.pitch;
    /* the power that fills half the full well at the spot's peak */
    photons = 0.5 * s.full_well * PI * wpx * wpx / 2 / exposure;
    memset(&h, 0, sizeof h);
    memcpy(h.p, hit, sizeof h.p);
    h.power = photons * PLANCK_HC / LAMBDA_M;
    h.path = path;
    memset(&src, 0, sizeof src);
    src.kind = IM_SPOT_HITS_GAUSS;
    src.hits = &h;
    src.nhits = 1;
    src.waist = r->beam_waist;
    src.beam_lambda = LAMBDA_M * 1e3;
    rc = F->synth(&s, &src, 1, (uint64_t)r->cam_seed + c->frames++, 1, &f, err, cap);
    if (rc) return -1;
    memset(&o, 0, sizeof o);
    o.method = IM_CM_GAUSS;
    o.gain = s.gain;
    o.read_noise = s.read_noise / s.gain;
    rc = F->centroid(c->cz, f, &o, &sp, 1, &res, err, cap);
    F->frame_free(f);
    if (rc) return -1;
    if (res.outcome == IM_FOUND_NONE) {
        snprintf(err, cap, "no spot in the camera frame (best candidate SNR %.3g)",
                 res.best_snr);
        return -1;
    }
    if (sp.flags & (IM_SF_EDGE | IM_SF_FIT_FAILED)) {
        snprintf(err, cap, "the spot at pixel (%.1f, %.1f) is %s", sp.x, sp.y,
                 sp.flags & IM_SF_EDGE ? "cut by the sensor's edge" : "not fitted");
        return -1;
    }
    {
        double dx = (sp.x - 0.5 * (s.width - 1)) * s.pitch;
        double dy = (sp.y - 0.5 * (s.height - 1)) * s.pitch;
        double y[3], x[3];
        axes(g, x, y);
        for (int k = 0; k < 3; k++) out->det[k] = g->detector[k] + dx * x[k] + dy * y[k];
    }
    out->sigma = s.pitch * sqrt(sp.sx * sp.sx + sp.sy * sp.sy);
    out->off = dist(out->det, hit);
    out->x = sp.x;
    out->y = sp.y;
    out->w = sp.w;
    out->snr = sp.snr;
    return 0;
}

void lm_rigcam_free(lm_rigcam *c)
{
    if (c->cz && c->im) c->im->frame->centroider_free(c->cz);
    memset(c, 0, sizeof *c);
}
