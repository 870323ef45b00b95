/* lensrx.c -- a lens file made ready for aimed rays (see lensrx.h): reading and
 * checking it, the missing answers, the first-order pupils and the trace_rx per
 * wavelength.  The steps are --pupil's (pupil.c), here shared for other dialogues;
 * a folded lens as --pupil takes one (first order unfolded, rays folded). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lensrx.h"

#define FILE_MAX (16 << 20)
#define DEG (3.14159265358979323846 / 180)

static char *slurp(const char *path, size_t *len, char *msg, size_t cap)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t n = 0, got;
    if (!f) { snprintf(msg, cap, "%s: cannot be read", path); return NULL; }
    buf = malloc(FILE_MAX + 1);
    if (!buf) { fclose(f); snprintf(msg, cap, "out of memory"); return NULL; }
    while ((got = fread(buf + n, 1, FILE_MAX + 1 - n, f)) > 0) n += got;
    fclose(f);
    if (n > FILE_MAX) {
        free(buf);
        snprintf(msg, cap, "%s: larger than 16 MiB: not a lens file", path);
        return NULL;
    }
    buf[n] = '\0';
    *len = n;
    return buf;
}

int lr_read_file(lm_io *io, const char *word, int finite_angles, ln_lens *out,
                 ln_notes *out_notes, char *msg, size_t cap)
{
    size_t len;
    char err[LN_ERR_MAX];
    char *text;
    ln_lens l;
    ln_notes notes = {0};
    int r, read_ok;
    /* the session's file registry (an input may not be an output of this session) */
    if (lm_check_input(io, word, "the lens file", msg, cap)) return 1;
    if (!(text = slurp(word, &len, msg, cap))) return 1;
    if (ln_is_zmx(text, len)) r = ln_read_zmx(text, len, word, &l, &notes, err, sizeof err);
    else r = ln_read_rx(text, len, word, &l, &notes, err, sizeof err);
    free(text);
    read_ok = r == LN_OK;
    if (r == LN_OK && ln_check(&l, word, err, sizeof err) != LN_OK) r = LN_BAD;
    if (r == LN_OK && ln_check_shape(&l, word, err, sizeof err) != LN_OK) r = LN_BAD;
    if (r == LN_OK && isinf(l.object) && l.nfield && l.field_kind == LN_FIELD_HEIGHT) {
        snprintf(err, sizeof err, "%s: object heights as fields need a finite object "
                 "(the object is at infinity: give field angles)", word);
        r = LN_BAD;
    }
    if (r == LN_OK && !finite_angles && !isinf(l.object) && l.nfield &&
        l.field_kind == LN_FIELD_ANGLE) {
        snprintf(err, sizeof err, "%s: field angles with a finite object: give the "
                 "fields as object heights", word);
        r = LN_BAD;
    }
    if (r == LN_OK && !isinf(l.object) && !(l.object > 0)) {
        snprintf(err, sizeof err, "%s: the object lies %s surface 1 (a virtual object): "
                 "rays are aimed only from a real object left of it, or from infinity",
                 word, l.object == 0 ? "on" : "right of");
        r = LN_BAD;
    }
    if (r == LN_OK && l.nsurf > PX_PUPIL_MAXSURF) {
        snprintf(err, sizeof err, "%s: %d surfaces: at most %d", word, l.nsurf,
                 PX_PUPIL_MAXSURF);
        r = LN_BAD;
    }
    if (r != LN_OK) {
        if (read_ok) ln_free(&l);
        ln_notes_free(&notes);
        snprintf(msg, cap, "%s", err);
        return 1;
    }
    *out = l;
    *out_notes = notes;
    return 0;
}

static int check_file(void *ctx, const char *word, char *msg, size_t cap)
{
    lr_lens *L = ctx;
    ln_lens l;
    ln_notes notes = {0};
    if (lr_read_file(L->c->io, word, L->finite_angles, &l, &notes, msg, cap)) return 1;
    if (L->have) ln_free(&L->lens);
    ln_notes_free(&L->notes);
    L->lens = l;
    L->notes = notes;
    L->have = 1;
    return 0;
}

int lr_ask_count(lr_lens *L, const char *q, const char *bad, int lo, int hi, int *v)
{
    return lm_ask_count(L->c->io, q, q, L->t->count_what, bad, lo, hi, v);
}

static int ask_missing(lr_lens *L)
{
    ln_lens *l = &L->lens;
    const lr_texts *t = L->t;
    char q[256];
    int rc;
    if (l->stop < 0) {
        int k;
        snprintf(q, sizeof q, t->stop, l->nsurf);
        if ((rc = lm_ask_count(L->c->io, q, q, t->stop_what, t->stop_bad, 1, l->nsurf, &k)))
            return rc;
        l->stop = k - 1;
    }
    if (l->ap_kind == LN_AP_NONE) {
        static const char *const kinds[] = {"epd", "fnum", "na", NULL};
        int i = 0;
        double v;
        if ((rc = calc_choice(L->c, t->ap_kind, t->ap_kind_what, kinds, &i)) ||
            (rc = calc_num(L->c, t->ap_value, t->ap_value_what, LM_POSITIVE, &v)))
            return rc;
        l->ap_kind = i == 0 ? LN_AP_EPD : i == 1 ? LN_AP_FNUM : LN_AP_NA;
        l->ap_value = v;
    }
    if (l->nfield == 0) {
        int n, inf = isinf(l->object);
        if ((rc = lr_ask_count(L, t->nfield, t->nfield_bad, 1, LR_MAXFIELD, &n))) return rc;
        l->field_kind = inf ? LN_FIELD_ANGLE : LN_FIELD_HEIGHT;
        for (int i = 0; i < n; i++) {
            double v;
            for (;;) {
                lm_mark m;
                snprintf(q, sizeof q, inf ? t->field_angle : t->field_height, i + 1);
                calc_mark(L->c, &m);
                if ((rc = calc_num(L->c, q, t->field_what, 0, &v))) return rc;
                if (!inf || fabs(v) < 90) break;
                if ((rc = calc_reject(L->c, &m, t->field_what, q, t->again_field, "%s",
                                      t->field_bad)))
                    return rc;
            }
            l->field[i].x = 0;
            l->field[i].y = v;
            l->field[i].weight = 1;
        }
        l->nfield = n;
    }
    return LM_GO;
}

int lr_ask_lens(lr_lens *L, calc *c, const lr_texts *t)
{
    char name[4096];
    int rc;
    L->c = c;
    L->t = t;
    rc = lm_ask_file(c->io, t->file, t->file, t->file_what, check_file, L, name, sizeof name);
    if (rc != LM_GO) return rc;
    if (L->notes.s && L->notes.len) {
        char *s = L->notes.s, *e;
        while (*s) {
            e = strchr(s, '\n');
            if (e) *e = '\0';
            calc_say(c, t->note, s);
            if (!e) break;
            s = e + 1;
        }
    }
    c->uname = L->lens.unit[0] ? L->lens.unit : "mm";
    return ask_missing(L);
}

/* The lens first-order optics sees: unfolded when folded. */
static const ln_lens *plens(const lr_lens *L) { return L->unf.nsurf ? &L->unf : &L->lens; }
static double real_z(const lr_lens *L, double u) { return L->zl + L->sig * (u - L->zl_u); }

static int pupil_at(const lr_lens *L, double lambda, px_pupil *p, char *why, size_t cap)
{
    const ln_lens *l = plens(L);
    px_pupil_in in = {L->cs, l->nsurf, l->stop, L->obj, lambda, PX_AP_EPD, l->ap_value,
                      isinf(l->object) ? INFINITY : l->object, isinf(l->object) ? 45 : 1};
    in.aperture = l->ap_kind == LN_AP_FNUM ? PX_AP_FNUM : l->ap_kind == LN_AP_NA ? PX_AP_NA
                                                                              : PX_AP_EPD;
    if (px_pupil_run(&in, p) != PX_OK) {
        snprintf(why, cap, "%s", p->why);
        return -1;
    }
    if (L->unf.nsurf) {                    /* image space into the folded frame */
        p->z_xp = real_z(L, p->z_xp);
        p->z_img = real_z(L, p->z_img);
    }
    return 0;
}

int lr_prepare(lr_lens *L, char *why, size_t cap)
{
    const ln_lens *l = &L->lens;
    double zl = 0;
    int nm = ln_mirrors(l);
    L->sig = nm % 2 ? -1 : 1;
    L->zl_u = 0;
    ln_free(&L->unf);
    if (nm || ln_breaks(l)) {
        if (ln_unfold(l, &L->unf, NULL, why, cap) != LN_OK) return -1;
        if (L->unf.nsurf > PX_PUPIL_MAXSURF) {
            snprintf(why, cap, "%d surfaces unfolded: at most %d", L->unf.nsurf,
                     PX_PUPIL_MAXSURF);
            return -1;
        }
        for (int i = 0; i + 1 < L->unf.nsurf; i++) L->zl_u += L->unf.surf[i].t;
    }
    for (int i = 0; i + 1 < l->nsurf; i++) zl += l->surf[i].t;
    L->zl = zl;
    if (ln_to_csurf(plens(L), L->cs, L->names, &L->obj, why, cap) != LN_OK) return -1;
    if (pupil_at(L, ln_primary(l), &L->prim, why, cap)) return -1;
    L->scale = fmax(fabs(L->prim.efl), L->prim.r_stop);
    if (l->surf[l->nsurf - 1].t * L->sig > 0) {   /* after odd mirrors: negative */
        L->z_image = zl + l->surf[l->nsurf - 1].t;
        L->image_from_file = 1;
    } else {
        L->z_image = L->prim.z_img;        /* infinite: afocal, the caller refuses */
        L->image_from_file = 0;
    }
    return 0;
}

void lr_rx_surface(const ln_surface *s, double z, trace_rx_surface *t)
{
    t->z = z;
    t->radius = isfinite(s->r) ? s->r : 0;
    t->conic = s->conic;
    t->nasph = s->nasph < TRACE_MAXASPH ? s->nasph : TRACE_MAXASPH;
    for (int k = 0; k < t->nasph; k++) t->asph[k] = s->asph[k];
    t->semi_diameter = s->semi;
    t->mirror = s->mirror;
    t->coordbrk = s->coordbrk;
    t->order = s->cb_order;
    t->decenter[0] = s->cb_dec[0];
    t->decenter[1] = s->cb_dec[1];
    for (int k = 0; k < 3; k++) t->tilt[k] = s->cb_tilt[k];
}

int lr_at(const lr_lens *L, double lambda, lr_wl *w, char *why, size_t cap)
{
    const ln_lens *l = &L->lens;
    double z = 0;
    w->lambda = lambda;
    if (pupil_at(L, lambda, &w->p, why, cap)) return -1;
    memset(w->surf, 0, sizeof w->surf);
    if (ln_index(l, -1, lambda, &w->rx.n_object, NULL, why, cap) != LN_OK) return -1;
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        trace_rx_surface *t = &w->surf[i];
        lr_rx_surface(s, z, t);
        if (ln_index(l, i, lambda, &t->n_right, NULL, why, cap) != LN_OK) return -1;
        z += s->t;
    }
    w->rx.nsurf = l->nsurf;
    w->rx.surf = w->surf;
    w->rx.stop = l->stop;
    w->rx.stop_radius = L->prim.r_stop;
    w->rx.z_image = L->z_image;
    w->s = L->prim.r_stop / w->p.r_stop;
    return 0;
}

void lr_request(const lr_lens *L, const lr_wl *w, const ln_field *f, double px, double py,
                trace_aim_req *rq)
{
    const px_pupil *p = &w->p;
    memset(rq, 0, sizeof *rq);
    rq->px = px;
    rq->py = py;
    if (isinf(L->lens.object)) {
        double tx = tan(f->x * DEG), ty = tan(f->y * DEG), n = sqrt(tx * tx + ty * ty + 1);
        rq->infinite = 1;
        rq->dir[0] = tx / n; rq->dir[1] = ty / n; rq->dir[2] = 1 / n;
        rq->z_ref = 0;
        rq->guess[0] = tx * p->yb[0] + px * p->y[0] * w->s;
        rq->guess[1] = ty * p->yb[0] + py * p->y[0] * w->s;
    } else {
        rq->obj[0] = f->x; rq->obj[1] = f->y; rq->obj[2] = -L->lens.object;
        rq->guess[0] = f->x * p->ub[0] + px * p->u[0] * w->s;
        rq->guess[1] = f->y * p->ub[0] + py * p->u[0] * w->s;
    }
}

void lr_free(lr_lens *L)
{
    ln_free(&L->unf);
    if (L->have) ln_free(&L->lens);
    L->have = 0;
    ln_notes_free(&L->notes);
}
