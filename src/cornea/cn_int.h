/* cn_int.h -- internals shared by the cornea engine's files (never by other engines). */
#ifndef CN_INT_H
#define CN_INT_H
#include "cornea.h"
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct cn_surf {
    double cf, cs, qf, qs;          /* flat/steep apex curvatures (1/mm) and Q */
    double alpha, ca, sa;           /* flat meridian angle, its cos and sin */
    double a4, a6;                  /* even asphere terms (CN_ASPHERE) */
    cn_bump bump;                   /* keratoconus-like bump (h 0: none) */
} cn_surf;

const char *cn_param_name(int k);
void cn_plane_of(const rg_geometry *g, cn_plane *pl);
void cn_surface(int model, const cn_params *p, cn_surf *s);
int cn_forward(int model, const cn_params *p, const double apex0[3], const cn_plane *pl,
               const cn_ray *r, double *u, double *v, double spot[3], double normal[3]);
void cn_params_from_cornea(const rg_cornea *c, const double apex0[3], double rx,
                           double ry, cn_params *p);
void cn_cornea_from_params(const rig_api *rg, int model, const cn_params *p,
                           const double apex0[3], rg_cornea *c);
int cn_ray_of_pose(const rig_api *rg, const rg_geometry *g, const rg_pose *pose,
                   cn_ray *r, char *err, size_t errcap);
int cn_simulate(const rig_api *rg, const rg_geometry *g, const rg_cornea *truth,
                const cn_scan_opts *o, cn_spot *spots, int cap, char *err, size_t errcap);
int cn_fit(const rg_geometry *g, cn_spot *spots, int n, const cn_params *start,
           const cn_fit_opts *o, cn_result *res, char *err, size_t errcap);
int cn_predict_scan(const rg_geometry *g, const cn_spot *spots, int n, int model,
                    int fix_tilt, const cn_params *p, double sigma, cn_predict *pr,
                    char *err, size_t errcap);
const char *cn_report(const cn_result *r, char *buf, size_t cap);
/* cn_model.c: the surface alone (eye frame) and the forward model with a bump */
int cn_sag(const cn_surf *s, double x, double y, double *z, double *zx, double *zy);
int cn_forward_bump(int model, const cn_params *p, const cn_bump *bump,
                    const double apex0[3], const cn_plane *pl, const cn_ray *r,
                    double *u, double *v, double spot[3], double normal[3]);
/* rig-frame point -> eye frame of p */
void cn_to_eye(const cn_params *p, const double apex0[3], const double x[3], double e[3]);
/* cn_zone.c: axial and tangential curvature (1/mm) at (x, y) along the meridian
 * through it; the 3 mm-zone Sim K of a surface */
int cn_curvatures(const cn_surf *s, double x, double y, double *axial, double *tang);
int cn_zone_simk(const cn_surf *s, double h, double *km, double *amp, double *steep_deg);
/* cn_map.c / cn_export.c */
int cn_reimage(const rg_geometry *g, int model, const cn_params *p, const cn_bump *bump,
               double sigma, unsigned long long seed, cn_spot *spots, int n);
int cn_map(int kind, int model, const cn_params *p, const cn_bump *bump, double hmax,
           int n, double *grid, double *aux);
void cn_spot_xy(const rg_geometry *g, const cn_result *r, const cn_spot *spots, int n,
                double *xy);
size_t cn_report_csv(const cn_result *r, const cn_spot *spots, int n, char *buf,
                     size_t cap);
size_t cn_report_json(const cn_result *r, const cn_spot *spots, int n, char *buf,
                      size_t cap);

/* cn_zern.c / cn_kc.c: the surface from the slopes, its maps and indices */
int cn_zterms(int order);
void cn_zbasis(int nt, double rho, double x, double y, double *v, double *gx, double *gy);
int cn_zfit_run(const rg_geometry *g, const cn_spot *spots, int n, const cn_params *ref,
                int ref_model, int max_order, cn_zfit *z, char *err, size_t errcap);
int cn_zsag(const cn_zfit *z, double x, double y, double *f, double *fx, double *fy);
int cn_zcovered(const cn_zfit *z, double x, double y);
void cn_zvertex(cn_zfit *z);
void cn_zlocal_vertex(cn_zfit *z);
int cn_zlocal(const cn_zfit *z, double x, double y, double *axial, double *tang,
              double *sd_axial);
int cn_zmap(int kind, const cn_zfit *z, double hmax, int n, double *grid, double *aux);
int cn_kc_of(const cn_zfit *z, cn_kc *k);
int cn_kc_model(int model, const cn_params *p, const cn_bump *bump, double zone_r, cn_kc *k);
int cn_kc_model_in(int model, const cn_params *p, const cn_bump *bump, const cn_params *frame,
                   double zone_r, cn_kc *k);

/* cn_analyse.c: Jacobian, SVD, covariance, determinacy, clinical numbers */
void cn_free_mask(int model, int fix_tilt, int free[CN_NPARAM]);
double cn_limit(int k);   /* sd above which parameter k is "not determined" */
void cn_free_mask_q(int model, int fix_tilt, int free_q, int free[CN_NPARAM]);
extern const double cn_step[CN_NPARAM];
int cn_jacobian(int model, const cn_params *p, const double apex0[3], const cn_plane *pl,
                const cn_spot *s, const int *idx, int nfree, double *row_u,
                double *row_v);
typedef struct cn_svd {
    int nfree, idx[CN_NPARAM];
    double sv[CN_NPARAM], vt[CN_NPARAM * CN_NPARAM], cond;
    double cov[CN_NPARAM * CN_NPARAM];
    unsigned undetermined;
    char why[512];
} cn_svd;
/* J: m x nfree weighted Jacobian (row-major). */
int cn_analyse(const double *J, int m, int model, const cn_params *p, double rcond,
               cn_svd *a);
void cn_clinical_of(int model, const cn_params *p, const double *cov,
                    unsigned undetermined, cn_clinical *k);
#endif
