/* fuzz_lens.c -- libFuzzer target for the lens model's readers (src/lens): the
 * thickness prescription (rx.c) and the OpticStudio .zmx (zmx.c, any encoding), and
 * the AGF glass catalogue reader (src/paraxial/agf.c).  The first byte picks the
 * reader: 'z' .zmx, 'r' prescription, 'a' AGF, anything else .zmx and prescription.  Every
 * input must give LN_OK or LN_BAD with a "NAME[:LINE]: ..." message, never a crash,
 * a leak or undefined behaviour.  A lens read must pass ln_check, and be written in
 * both formats and read back: the same format keeps every value, the other reads. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lens/lens.h"
#include "paraxial/paraxial.h"

static void expect_message(int rc, const char *err)
{
    if (rc && (!err[0] || !strstr(err, "fuzz."))) abort();
}

/* No wavelength means the d line, no field the axis: as the .zmx writer spells them. */
static void canon(ln_lens *l)
{
    if (l->nwl == 0) { l->nwl = 1; l->wl[0] = PX_LAMBDA_D; l->wl_weight[0] = 1; }
    if (l->nfield == 0) { l->nfield = 1; l->field[0].x = l->field[0].y = 0; l->field[0].weight = 1; }
}

/* NULL if every value of a and b is the same, else what differs. */
static const char *differ(const ln_lens *a0, const ln_lens *b0)
{
    ln_lens ca = *a0, cb = *b0;          /* shallow: only compared */
    const ln_lens *a = &ca, *b = &cb;
    canon(&ca);
    canon(&cb);
    if (a->nsurf != b->nsurf) return "nsurf";
    if (a->stop != b->stop) return "stop";
    if (a->nwl != b->nwl) return "nwl";
    if (a->nfield != b->nfield || a->field_kind != b->field_kind) return "fields";
    if (a->ap_kind != b->ap_kind || a->ap_value != b->ap_value) return "aperture";
    if (a->object != b->object) return "object";
    if (strcmp(a->obj_glass, b->obj_glass) || a->obj_nd != b->obj_nd || a->obj_vd != b->obj_vd)
        return "object medium";
    if (a->image_c != b->image_c || a->image_semi != b->image_semi) return "image";
    if (strcmp(a->title, b->title)) return "title";
    if (strcmp(a->unit, b->unit)) return "unit";
    for (int i = 0; i < a->nwl; i++)
        if (a->wl[i] != b->wl[i] || a->wl_weight[i] != b->wl_weight[i]) return "wavelength";
    for (int i = 0; i < a->nfield; i++)
        if (a->field[i].x != b->field[i].x || a->field[i].y != b->field[i].y ||
            a->field[i].weight != b->field[i].weight) return "field";
    for (int i = 0; i < a->nsurf; i++) {
        const ln_surface *s = &a->surf[i], *t = &b->surf[i];
        if (s->c != t->c) return "curvature";
        if (s->t != t->t) return "thickness";
        if (strcmp(s->glass, t->glass) || s->nd != t->nd || s->vd != t->vd) return "glass";
        if (s->semi != t->semi) return "semi";
        if (s->conic != t->conic) return "conic";
        if (s->mirror != t->mirror) return "mirror";
        for (int k = 0; k < s->nasph && k < t->nasph; k++)
            if (s->asph[k] != t->asph[k]) return "asphere";
    }
    return NULL;
}

/* Written in format w (1 .zmx, 0 prescription) and read back. */
static void again(const ln_lens *l, int w, int must_equal)
{
    char err[LN_ERR_MAX], *text = w ? ln_write_zmx(l) : ln_write_rx(l);
    ln_lens m;
    int rc;
    if (!text) abort();
    rc = w ? ln_read_zmx(text, strlen(text), "fuzz.out", &m, NULL, err, sizeof err)
           : ln_read_rx(text, strlen(text), "fuzz.out", &m, NULL, err, sizeof err);
    if (rc != LN_OK) {
        fprintf(stderr, "written %s does not read back: %s\n---\n%s\n", w ? "zmx" : "rx",
                err, text);
        abort();
    }
    if (must_equal && differ(l, &m)) {
        fprintf(stderr, "written %s reads back different (%s)\n---\n%s\n", w ? "zmx" : "rx",
                differ(l, &m), text);
        abort();
    }
    ln_free(&m);
    free(text);
}

static void one(const char *p, size_t n, int zmx)
{
    char err[LN_ERR_MAX] = "";
    ln_lens l;
    ln_notes notes = {0};
    int rc = zmx ? ln_read_zmx(p, n, "fuzz.zmx", &l, &notes, err, sizeof err)
                 : ln_read_rx(p, n, "fuzz.rx", &l, &notes, err, sizeof err);
    expect_message(rc, err);
    ln_notes_free(&notes);
    if (rc) return;
    if (ln_check(&l, "fuzz.check", err, sizeof err) != LN_OK) abort();
    again(&l, zmx, 1);
    again(&l, !zmx, 0);
    {
        px_system s;
        if (ln_paraxial(&l, ln_primary(&l), &s, err, sizeof err) == LN_OK) {
            px_first f;
            (void)px_first_order(&s, &f);
            px_system_free(&s);
        }
    }
    ln_free(&l);
}

/* An AGF glass catalogue (src/paraxial/agf.c): PX_OK, or PX_BAD with a message;
 * every glass's formula evaluated (NaN allowed, a crash not). */
static void agf(const char *p, size_t n)
{
    char err[1024] = "";
    px_glass_cat c;
    int rc = px_agf_read(p, n, "FUZZ", "fuzz.agf", &c, err, sizeof err);
    if (rc != PX_OK) { if (!strstr(err, "fuzz.agf")) abort(); return; }
    for (int i = 0; i < c.n; i++)
        for (double l = 0.3; l < 3; l *= 1.7) (void)px_glass_formula(&c.rec[i], l);
    px_agf_free(&c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *p = (const char *)data + 1;
    if (size == 0) return 0;
    if (data[0] == 'a') { agf(p, size - 1); return 0; }   /* 'a': an AGF catalogue */
    if (data[0] != 'r') one(p, size - 1, 1);
    if (data[0] != 'z') one(p, size - 1, 0);
    return 0;
}
