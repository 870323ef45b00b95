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
/* The rig file (rg_file.c; format in README "Rig files"): the chip, one block per
 * joint axis (STEP/DIR/ENABLE outputs, home switch input, steps per degree or mm,
 * travel, speed, acceleration), the laser-enable output, the interlock input, the
 * heartbeat output and the geometry keys (rg_geometry, read by the geometry part). */
#define RG_ERRMAX 512
#define RG_NAMEMAX 64
typedef struct rg_line {
    int offset;                 /* line offset on the chip; -1: none */
    int active_low;             /* 1: the active state is the low level */
    int at;                     /* rig-file line that named it (messages) */
} rg_line;
typedef struct rg_axis {
    rg_line step, dir, enable, home;    /* enable and home may be absent (-1) */
    int linear;                 /* 1: a stage in mm (u, v); 0: an angle in degrees */
    double steps_per;           /* steps per degree or per mm (> 0) */
    double min, max;            /* travel, degrees or mm */
    double speed, accel;        /* maximum speed (/s) and acceleration (/s^2) */
    double home_at;             /* the joint value where the home switch trips */
    int home_dir;               /* -1 or +1: the way homing seeks the switch */
    double home_speed;          /* homing speed (/s) */
    int dir_invert;             /* 1: positive moves drive DIR inactive */
    int sim_home_broken;        /* simulator: this home switch never trips */
    int at;                     /* rig-file line of its "axis" line; 0: missing */
} rg_axis;
typedef struct rg_rig {
    char path[256];
    char chip[RG_NAMEMAX];      /* gpiod chip name, path or number */
    rg_axis axis[RG_NJOINTS];   /* indexed by RG_J_* */
    rg_line laser;              /* laser-enable output (required) */
    rg_line interlock;          /* interlock input (required): active = closed = safe */
    rg_line heartbeat;          /* charge-pump output toggled while the laser is on */
    double max_on_ms;           /* longest exposure */
    double tick_us;             /* control step: one step edge pair per axis at most */
    double heartbeat_timeout_ms;/* the pump circuit's hold time (simulator, README) */
    double home_timeout_s;      /* a home switch that never trips: give up */
    double settle_ms;           /* wait after a move before the laser may go on */
    int sim_realtime;           /* simulator paced by the real clock (kill tests) */
    int sim_interlock_open;     /* simulator: the interlock is open from the start */
    double sim_interlock_open_ms; /* simulator: it opens at this time (ms); < 0 never */
    int geom_keys;              /* number of geometry lines read */
    rg_geometry geom;
} rg_rig;

enum rg_backend { RG_BACKEND_SIM, RG_BACKEND_GPIOD, RG_BACKEND_NULL };
typedef struct rg_open_opts {
    int backend;                /* enum rg_backend; NULL: do-nothing lines, real clock */
    const char *chip;           /* gpiod: overrides the rig file's chip; NULL: keep */
    const char *sim_log;        /* simulator: event log (written as LOG.part, renamed
                                   when the machine closes or stops); NULL: none */
    const char *sim_state;      /* simulator: its chip state in this shared file, so a
                                   watchdog outside the process sees the lines; NULL */
    int realtime;               /* 1: try SCHED_FIFO and mlockall */
} rg_open_opts;
typedef struct rg_machine rg_machine;
typedef int (*rg_stop_fn)(void *ctx);   /* non-zero: stop now */
typedef struct rg_timing {              /* step-edge lateness on the real clock */
    long edges;
    double p50_us, p99_us, max_us;
} rg_timing;
/* The simulator's chip state (a shared file when rg_open_opts.sim_state is set): what
 * a watchdog process reads.  Levels are logical (1 = active). */
typedef struct rg_sim_shared {
    char magic[8];              /* "lmrigsim" */
    volatile int64_t now_ns;            /* simulated time */
    volatile int32_t laser, interlock, light, pid;
    volatile int32_t enable[RG_NJOINTS];
    volatile int64_t steps[RG_NJOINTS]; /* motor positions, steps */
    volatile int64_t heartbeat_edges;   /* toggles so far */
    volatile int64_t heartbeat_last_ns; /* simulated time of the last toggle */
    volatile int64_t timeout_ns;        /* the pump's hold time */
} rg_sim_shared;
/* ==== end of the machine ========================================================= */


typedef struct rig_api {
    int abi;                                   /* RIG_ABI */
    const char *(*version)(void);
    /* ---- geometry ---- */
    /* (geometry entry points, in this block) */
    /* ---- the machine ---- */
    /* The rig file: 0, or RG_EINVAL with "FILE:LINE: why" in err (cap bytes). */
    int (*rig_load)(const char *path, rg_rig *rig, char *err, size_t cap);
    int (*rig_parse)(const char *text, size_t len, const char *name, rg_rig *rig,
                     char *err, size_t cap);
    /* Joints (rad, mm) to motor steps, each checked against travel: 0 or RG_ETRAVEL. */
    int (*pose_steps)(const rg_rig *rig, const rg_pose *p, long steps[RG_NJOINTS],
                      char *err, size_t cap);
    /* Open the lines (laser off, drivers disabled), check the interlock reads. */
    int (*open)(const rg_rig *rig, const rg_open_opts *o, rg_machine **m, char *err,
                size_t cap);
    const char *(*sched_note)(const rg_machine *m);   /* what real-time scheduling got */
    int (*home)(rg_machine *m, rg_stop_fn stop, void *ctx, char *err, size_t cap);
    /* A coordinated trapezoidal move to joint values p; refused before the first
     * pulse if any joint is outside travel or the machine is not homed. */
    int (*move)(rg_machine *m, const rg_pose *p, rg_stop_fn stop, void *ctx, char *err,
                size_t cap);
    int (*move_steps)(rg_machine *m, const long steps[RG_NJOINTS], rg_stop_fn stop,
                      void *ctx, char *err, size_t cap);
    /* Laser on for ms (<= max_on_ms), only with the interlock closed and every axis
     * at rest; off within one control step when the interlock opens (RG_EINTERLOCK). */
    int (*expose)(rg_machine *m, double ms, rg_stop_fn stop, void *ctx, char *err,
                  size_t cap);
    void (*position)(const rg_machine *m, long steps[RG_NJOINTS], rg_pose *p);
    int (*homed)(const rg_machine *m);
    void (*timing)(const rg_machine *m, rg_timing *t);
    /* Laser off, then drivers disabled, lines released, log closed: 0 or RG_EIO. */
    int (*close)(rg_machine *m);
    /* Async-signal-safe: every open machine's laser off, then its drivers disabled
     * (and the simulator's log completed).  For a signal handler or stop hook. */
    void (*emergency_off)(void);
} rig_api;

typedef const rig_api *(*rig_get_api_fn)(int abi);
const rig_api *rig_get_api(int abi);

#endif
