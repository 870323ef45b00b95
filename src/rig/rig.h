/* rig.h -- public face of the cornea-rig engine (sections 33, 36-39): the geometry of
 * the two deflection mirrors (solve a pose for a target point on the cornea, forward
 * check, quantisation to motor steps), and the machine (rig file, stepper axes and the
 * laser on libgpiod 1.6 or a simulated chip, motion profiles, safety).  Lives in
 * build/lib/lensmat-rig.so, loaded only by rig sessions:
 *     rig_get_api_fn get = (rig_get_api_fn)lm_engine_symbol("rig", RIG_API_SYMBOL);
 *     const rig_api *rg = get ? get(RIG_ABI) : NULL;
 * The engine never prints and never exits: functions return 0 (RG_OK) or a negative
 * RG_E* code with a message in err.  Units: mm and radians inside; the rig file and
 * the dialogue say degrees.
 *
 * Two parts, each with its own section: geometry (rg_geom*.c, rg_quant*.c) and the
 * machine (rg_file.c, rg_gpiod.c, rg_sim.c, rg_motion.c, rg_safety.c). */
#ifndef RIG_H
#define RIG_H
#include <stddef.h>
#include <stdint.h>

#define RIG_ABI 1
#define RIG_API_SYMBOL "rig_get_api"

enum { RG_OK = 0, RG_EINVAL = -1, RG_ENOMEM = -2, RG_EIO = -3, RG_ESTOP = -4,
       RG_EUNREACH = -5, RG_ETRAVEL = -6, RG_EINTERLOCK = -7, RG_EBUSY = -8,
       RG_ETIMEOUT = -9, RG_EABI = -10 };

/* ==== geometry (section 38) ====================================================== */
/* The contract between the geometry and the machine: the rig file fills rg_geometry,
 * the geometry solves an rg_pose (six joints), the machine moves to it.  Fields may be
 * added at the end of each struct; none is renamed. */
enum rg_cornea_model { RG_SPHERE, RG_CONIC, RG_ASPHERE, RG_BICONIC };
typedef struct rg_cornea {
    int model;                  /* enum rg_cornea_model */
    double R, Q;                /* apex radius (mm) and conic constant (flat meridian) */
    double R2, Q2;              /* biconic: the steep meridian */
    double axis;                /* biconic: angle of the flat meridian (rad) */
    int nasph;                  /* asphere: coefficients a4, a6, ... (section 33) */
    double asph[8];
    double rot[9];              /* pose of the eye: row-major rotation, eye to rig */
    double trans[3];            /* apex position in the rig frame */
} rg_cornea;
typedef struct rg_gimbal {      /* a two-axis mirror mount */
    double center[3];           /* the point the two rotation axes meet */
    double axis1[3], axis2[3];  /* outer and inner rotation axes at the zero pose */
    double normal0[3];          /* mirror normal at the zero pose */
    double offset;              /* mirror surface from the axes' point along the normal
                                   (thickness, gimbal offset); 0: on the axes */
    double radius;              /* mirror semi-diameter (blocking tests) */
} rg_gimbal;
typedef struct rg_geometry {
    double laser_at[3], laser_dir[3];   /* the fixed beam */
    rg_gimbal m1;                       /* centre fixed on the beam line */
    rg_gimbal m2;                       /* centre moves on the plane p2 */
    double p2_at[3], p2_u[3], p2_v[3];  /* p2: origin and its two stage axes (unit) */
    double detector[3];                 /* the fixed detector point */
    rg_cornea cornea;
} rg_geometry;
/* Joint values: m1's two angles, m2's stage position on p2, m2's two angles. */
enum { RG_J_M1A, RG_J_M1B, RG_J_U, RG_J_V, RG_J_M2A, RG_J_M2B, RG_NJOINTS };
typedef struct rg_pose { double j[RG_NJOINTS]; } rg_pose;   /* rad, mm, rad */
/* (the geometry part's further declarations go here) */
/* ==== end of geometry ============================================================ */


/* ==== the machine ================================================================ */
/* (the machine part's declarations go here) */
/* ==== end of the machine ========================================================= */


typedef struct rig_api {
    int abi;                                   /* RIG_ABI */
    const char *(*version)(void);
    /* ---- geometry ---- */
    /* (geometry entry points, in this block) */
    /* ---- the machine ---- */
    /* (machine entry points, in this block) */
} rig_api;

typedef const rig_api *(*rig_get_api_fn)(int abi);
const rig_api *rig_get_api(int abi);

#endif
