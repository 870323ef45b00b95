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
 * machine (rg_file.c, rg_gpiod.c, rg_sim.c, rg_motion.c, rg_safety.c, rg_dose.c; the
 * safety functions: doc/rig-safety.md). */
#ifndef RIG_H
#define RIG_H
#include <stddef.h>
#include <stdint.h>

#define RIG_ABI 3               /* 2: rg_spot_pose, rg_spots' scan fields, cornea_curvature,
                                   spot_chain, spot_pose (the cornea's oblique incidence);
                                   3: the laser's polarization, each pose's Fresnel
                                   reflectance and photons, the lens balanced over the scan */
#define RIG_API_SYMBOL "rig_get_api"

enum { RG_OK = 0, RG_EINVAL = -1, RG_ENOMEM = -2, RG_EIO = -3, RG_ESTOP = -4,
       RG_EUNREACH = -5, RG_ETRAVEL = -6, RG_EINTERLOCK = -7, RG_EBUSY = -8,
       RG_ETIMEOUT = -9, RG_EABI = -10, RG_EFAULT = -11, RG_EDOSE = -12 };

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
    double zone;                /* measurable zone: largest height (mm; 0: the cap) */
} rg_cornea;
typedef struct rg_gimbal {      /* a two-axis mirror mount */
    double center[3];           /* the point the two rotation axes meet */
    double axis1[3], axis2[3];  /* outer and inner rotation axes at the zero pose */
    double normal0[3];          /* mirror normal at the zero pose */
    double offset;              /* mirror surface from the axes' point along the normal
                                   (thickness, gimbal offset); 0: on the axes */
    double radius;              /* mirror semi-diameter (blocking tests) */
    double mount_radius;        /* mount body: cylinder behind the mirror (0: radius) */
    double mount_depth;         /* its depth behind the surface (0: none) */
} rg_gimbal;
/* One joint's resolution and travel, in the joint's units (rad or mm). */
typedef struct rg_joint {
    double steps_per;          /* steps per rad (angles) or per mm (stage); 0: continuous */
    double lo, hi;             /* travel limits (lo < hi; both 0: unlimited) */
} rg_joint;
typedef struct rg_geometry {
    double laser_at[3], laser_dir[3];   /* the fixed beam */
    rg_gimbal m1;                       /* centre fixed on the beam line */
    rg_gimbal m2;                       /* centre moves on the plane p2 */
    double p2_at[3], p2_u[3], p2_v[3];  /* p2: a point of it and its two stage axes */
    double detector[3];                 /* the fixed detector point */
    rg_cornea cornea;
    rg_joint joint[6];                  /* per joint (RG_J_*): steps and travel; the
                                           rig-file reader fills these from its axes */
} rg_geometry;
/* Joint values: m1's two angles, m2's stage position on p2, m2's two angles. */
enum { RG_J_M1A, RG_J_M1B, RG_J_U, RG_J_V, RG_J_M2A, RG_J_M2B, RG_NJOINTS };
typedef struct rg_pose { double j[RG_NJOINTS]; } rg_pose;   /* rad, mm, rad */

/* --- frames and conventions ------------------------------------------------------
 * Eye frame: apex at the origin, optical axis +z pointing INTO the eye, so the
 * cornea is z = f(x, y) >= 0 and its outward normal at the apex is -z; light comes
 * from z < 0.  cornea.rot / cornea.trans map it to the rig frame:
 *     p_rig = rot * p_eye + trans.
 * Sag (s^2 = x^2 + y^2):
 *   RG_SPHERE   z = s^2 / (R (1 + sqrt(1 - s^2/R^2)))
 *   RG_CONIC    z = s^2 / (R (1 + sqrt(1 - (1+Q) s^2/R^2)))   (Q: -1 parabola)
 *   RG_ASPHERE  the conic + sum_i asph[i] s^(4+2i)             (section 33: A2 s^4 ...)
 *   RG_BICONIC  with (x', y') the eye frame turned by `axis` about z (x' along the
 *               flat meridian):  z = (x'^2/R + y'^2/R2) /
 *                 (1 + sqrt(1 - (1+Q) x'^2/R^2 - (1+Q2) y'^2/R2^2))
 * A target point on the cornea (rg_target) is given by
 *   RG_T_ANGLES  theta, phi: spherical coordinates about the apex centre of
 *                curvature (0,0,R) (section 38): the point where the ray from that
 *                centre at polar angle theta from -z and azimuth phi (from +x toward
 *                +y) meets the surface; for a sphere, exactly the sphere's (theta,phi);
 *   RG_T_HEIGHT  height h (mm from the axis) and meridian phi: (h cos phi, h sin phi,
 *                f(x, y)) in the eye frame.
 * Gimbals: n(a, b) = Rot(axis1, a) Rot(axis2, b) normal0 (the inner axis turns with
 * the outer one: axis2 is its direction at the zero pose).  The mirror surface is
 * the plane through center + offset * n with normal n (n: the reflecting side).
 * Stage: m2's gimbal centre at stage (u, v) is m2.center + u p2_u + v p2_v (m2.center
 * lies on p2: its centre at u = v = 0).  Joint 0 everywhere = the zero pose.
 *
 * --- rig-file keys of the geometry (parsed by rg_geometry_key) --------------------
 * One key and its values per line; lengths in mm, angles in degrees:
 *   laser_at X Y Z          laser_dir X Y Z        the fixed beam
 *   m1_center X Y Z         m2_center X Y Z        gimbal centres (m2's at u = v = 0,
 *                                                  on p2)
 *   mN_axis1 X Y Z          mN_axis2 X Y Z         outer and inner rotation axes
 *   mN_normal X Y Z                                mirror normal at the zero pose
 *   mN_offset D             mN_radius R            surface off the axes; semi-diameter
 *   mN_mount_radius R       mN_mount_depth D       mount body (blocking tests)
 *   p2_at X Y Z   p2_u X Y Z   p2_v X Y Z          stage plane and axes
 *   detector X Y Z
 *   cornea sphere|conic|asphere|biconic
 *   cornea_R R   cornea_Q Q   cornea_R2 R   cornea_Q2 Q   cornea_axis DEG
 *   cornea_asph A4 A6 ...   (up to RG_MAXASPH)        cornea_zone H (0: whole cap)
 *   eye_at X Y Z            apex position in the rig frame
 *   eye_rot RX RY RZ        eye rotation, degrees, about x then y then z
 *   joint NAME STEPS_PER LO HI   NAME one of m1a m1b u v m2a m2b (rg_joint_names):
 *                           steps per degree (angles) or per mm (u, v; 0: continuous)
 *                           and travel limits in degrees or mm
 * Vectors need not be unit (normalised by rg_geometry_check).  Keys the machine
 * owns (axes, lines, laser) are not geometry keys: rg_geometry_key says "not mine"
 * (returns 1) so the reader can try its own table. */
#define RG_MAXASPH 7

/* Names of the joints in rig files and messages: "m1a" "m1b" "u" "v" "m2a" "m2b". */

enum rg_target_kind { RG_T_ANGLES, RG_T_HEIGHT };
typedef struct rg_target {
    int kind;                  /* enum rg_target_kind */
    double a, b;               /* theta, phi (rad) or h (mm), phi (rad) */
} rg_target;

/* Diagnostics: bits of rg_solution.diag / rg_beam.diag.  RG_D_FATAL bits make solve
 * fail (RG_EUNREACH, or RG_ETRAVEL for RG_D_TRAVEL alone); the others are warnings
 * the caller states (RG_D_ILLCOND with the condition number). */
enum rg_diag {
    RG_D_OFF_CORNEA    = 1 << 0,   /* target beyond the zone or the conic's edge */
    RG_D_DETECTOR_SIDE = 1 << 1,   /* detector behind the tangent plane at the target */
    RG_D_PARALLEL_P2   = 1 << 2,   /* backward ray (nearly) parallel to p2 */
    RG_D_BEHIND_P2     = 1 << 3,   /* backward ray meets p2 behind the cornea */
    RG_D_M2_BLOCKS     = 1 << 4,   /* m2 or its mount blocks the ray to the detector
                                      (or the laser on its way to m1) */
    RG_D_M1_BLOCKS     = 1 << 5,   /* m1 or its mount blocks the beam */
    RG_D_MISS_MIRROR   = 1 << 6,   /* beam lands outside a mirror's semi-diameter */
    RG_D_GRAZING       = 1 << 7,   /* incidence on a mirror or the cornea beyond
                                      max_incidence */
    RG_D_GIMBAL        = 1 << 8,   /* a mount cannot turn its mirror to that normal */
    RG_D_TRAVEL        = 1 << 9,   /* a joint outside its travel */
    RG_D_NO_CONVERGE   = 1 << 10,  /* the exact model (mirror offsets) not solved */
    RG_D_MISS_CORNEA   = 1 << 11,  /* forward: the beam misses the cornea */
    RG_D_ILLCOND       = 1 << 12,  /* warning: joints-to-spot map ill-conditioned */
    RG_D_NEAR_PARALLEL = 1 << 13,  /* warning: backward ray within 2x the p2 limit */
    RG_D_TRACE_MISS    = 1 << 14,  /* the trace engine's beam missed target or detector
                                      by more than trace_tol (a bug: never seen) */
    RG_D_FATAL         = ((1 << 12) - 1) | (1 << 14)
};

struct trace_api;              /* src/trace/trace.h: the caller passes the engine table */
typedef struct rg_solve_opts {
    double min_p2_angle;       /* smallest angle backward ray / p2 (rad; 0: 2 deg) */
    double max_incidence;      /* largest incidence, mirrors and cornea (rad; 0: 80 deg) */
    double cond_max;           /* RG_D_ILLCOND above this (0: 1e4) */
    double tol;                /* Newton residual, mm (0: 1e-12) */
    int max_iter;              /* Newton iterations (0: 30) */
    int no_checks;             /* 1: skip the condition number (baseline timing only) */
    int newton_only;           /* 1: mirror offsets by Newton alone, from the zero-offset
                                  closed form (tests: the two methods must agree) */
    const struct trace_api *trace;  /* non-NULL: every solution also traced through
                                       the trace engine (rig_api.verify) */
    double trace_tol;          /* largest traced miss accepted (mm; 0: 1e-6) */
} rg_solve_opts;

/* The beam through a pose (forward model, exact: offsets, finite mirrors). */
typedef struct rg_beam {
    unsigned diag;             /* RG_D_* found along the way */
    double h1[3], h2[3];       /* where the beam meets m1's and m2's surfaces */
    double d1[3], d2[3];       /* directions leaving m1 and m2 */
    double spot[3];            /* on the cornea (rig frame) */
    double normal[3];          /* outward cornea normal there */
    double d3[3];              /* direction reflected by the cornea */
    double det[3];             /* where it crosses the detector plane (through the
                                  detector point, normal along apex->detector: a
                                  camera looking at the eye); NaN: never */
    double inc1, inc2, inc3;   /* incidence angles at m1, m2, cornea (rad) */
} rg_beam;

typedef struct rg_solution {
    rg_pose pose;
    unsigned diag;             /* RG_D_* */
    double target[3], normal[3];   /* target point and outward normal (rig frame) */
    double back[3];            /* unit backward ray, target toward m2 */
    double p2_angle;           /* angle between the backward ray and p2 (rad) */
    double cond;               /* condition number of the joints-to-spot map */
    int iterations;            /* offsets: construction passes + Newton steps (0:
                                  mirrors on their axes, the closed form is exact) */
    double residual;           /* largest model residual at the end (mm) */
    rg_beam beam;              /* the forward model through the pose */
    double traced_err;         /* with opts->trace: the traced beam's largest miss of
                                  target and detector point (mm); else NaN */
} rg_solution;

/* Quantised pose: stage first, angles re-solved for the quantised centre, then m1's
 * angles (each grid corner around them), m2's re-aimed at the target and rounded (the
 * nearest landing of the 4 wins); the landing errors of that pose on the exact
 * forward model.  Steps count from the zero pose (joint 0). */
typedef struct rg_quantised {
    rg_pose pose;              /* commanded (on the step grid) */
    int64_t steps[RG_NJOINTS]; /* step counts from the zero pose */
    unsigned diag;
    double err_cornea;         /* |spot - target| (mm) */
    double err_detector;       /* miss at the detector point, in its plane (mm) */
    double err_cornea_resolved;    /* the same before angles are quantised (mm) */
    double err_detector_resolved;
    rg_beam beam;
} rg_quantised;

/* Result of a forward trace through the trace engine (independent check). */
typedef struct rg_verify {
    int hit;                   /* 1: the traced beam reached the detector via m1, m2
                                  and a cornea reflection */
    double spot[3], det[3];    /* traced points on the cornea and the detector plane */
    double err_target;         /* |traced spot - target| (mm) */
    double err_detector;       /* |traced detector hit - detector point| (mm) */
    double reflect_err;        /* largest reflection-law defect seen at any mirror or
                                  the cornea, |d_out - (d_in - 2(d_in.n)n)| */
} rg_verify;

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
    /* (added by the safety work: doc/rig-safety.md) */
    rg_line limit;              /* hard-limit switch input (both ends in series); -1 */
    double home_pulloff;        /* homing pull-off distance (deg or mm; default 0.5) */
    double home_locate_speed;   /* slow locate speed (/s; default home_speed / 10) */
    double sim_limit_ms;        /* simulator: the limit switch trips at this time; < 0 */
    double sim_lose_step_ms;    /* simulator: the driver drops one pulse after this; < 0 */
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
    /* the camera at the detector point, for closed-loop frames (README "Rig files") */
    int cam_frames;             /* camera frames|none: 1 = scans check synthetic frames */
    double cam_pitch;           /* camera_pitch MM (default 0.02) */
    int cam_pixels;             /* camera_pixels N: an N x N sensor (default 128) */
    double cam_read_noise;      /* camera_read_noise E: electrons rms (default 5) */
    double cam_seed;            /* camera_seed N: noise seed of the first frame (default 1) */
    double beam_waist;          /* beam_waist MM: the laser's waist radius (default 0.2) */
    /* ---- safety (doc/rig-safety.md) ---- */
    int eye_safe_without_heartbeat; /* "eye_safe_without_heartbeat yes": emission allowed
                                       with no heartbeat line (said in words) */
    double laser_power_mw;      /* power at the cornea (mW); 0: not given: no emission */
    double wavelength_nm;       /* the laser's wavelength (nm) */
    double beam_diameter_mm;    /* 1/e^2 beam diameter at the cornea (mm) */
    rg_line key_switch;         /* input: active = key on (emission allowed); -1 */
    rg_line indicator;          /* output: emission indicator, on before and during */
    rg_line shutter;            /* output: beam shutter, active = open */
    double emission_delay_ms;   /* indicator on this long before the laser may emit */
    double shutter_ms;          /* shutter travel time (open and close) */
    double step_pulse_us;       /* the drivers' minimum STEP high time (default 5) */
    double max_late_us;         /* a STEP edge later than this stops the motion
                                   (default tick_us / 2) */
    double home_debounce_ms;    /* homing: the switch re-read after this (default 10) */
    double sim_interlock_close_ms; /* simulator: the interlock closes again; < 0 never */
    double sim_key_off_ms;      /* simulator: the key switch turns off at this time */
    double sim_stall_at_ms;     /* simulator: the controller is preempted at this time */
    double sim_stall_ms;        /* ... for this long (a missed deadline) */
    int expose_moving;          /* "expose_moving yes": the laser may pulse while the axes
                                   move (rig_api.sweep, doc/scan-time.md); 0: never */
    /* ---- the laser's Gaussian beam (rg_spots.c, doc/rig.md "The beam on the cornea
     * and the detector"); beam_waist above is its waist radius when given */
    int beam_waist_line;        /* rig-file line of 'beam_waist'; 0: not given (the
                                   waist then reproduces beam_diameter_mm, below) */
    double beam_waist_at;       /* beam_waist_at_mm Z: the waist lies Z mm before m1
                                   along the beam (negative: past it); NaN: at the laser */
    double beam_m2;             /* beam_m2 M2 (>= 1; default 1) */
    double lens_f, lens_at;     /* focus_lens_mm F AT: a thin lens of focal length F
                                   (mm, +-) AT mm before the cornea apex on the
                                   m2-cornea leg; lens_at 0: none */
    int lens_line;              /* its rig-file line (0: none) */
    /* laser_polarization X Y Z | unpolarized: the field's direction as the beam leaves
     * the laser (projected perpendicular to laser_dir; the mirrors ideal, rs = -rp),
     * for the cornea's Fresnel reflectance pose by pose (rg_spotscan.c) */
    int laser_pol_set;          /* 1: linear along laser_pol; 0: unpolarized (default) */
    double laser_pol[3];
    int laser_pol_line;         /* its rig-file line (0: none) */
} rg_rig;

/* Latched faults (LinuxCNC's estop_latch model): the first one is kept; laser off
 * first, then drivers off; only rig_api.reset clears it, refused while the cause
 * persists. */
enum rg_fault_cause { RG_F_NONE, RG_F_INTERLOCK, RG_F_LIMIT, RG_F_DEADLINE,
                      RG_F_HEARTBEAT, RG_F_LOSTSTEP, RG_F_KEY, RG_F_HOMING };

/* The dose at the cornea against the maximum permissible exposure (rg_dose.c): the
 * session's exposures so far plus n more of ms each. */
typedef struct rg_dose {
    double E_peak;              /* peak irradiance of the Gaussian beam (W/m^2) */
    double E_aperture;          /* irradiance averaged over the 7 mm limiting aperture */
    double H_one;               /* radiant exposure of one exposure (J/m^2, aperture) */
    double mpe_one;             /* MPE for one exposure's duration (J/m^2) */
    long n;                     /* exposures: the session's plus the planned */
    double t_total;             /* their summed on-time (s) */
    double H_total;             /* their summed radiant exposure (J/m^2) */
    double mpe_total;           /* MPE for t_total as one exposure (J/m^2) */
    double fraction;            /* the larger of H_one/mpe_one and H_total/mpe_total */
    const char *limit;          /* which row of which table gave the limit */
} rg_dose;

enum rg_backend { RG_BACKEND_SIM, RG_BACKEND_GPIOD, RG_BACKEND_NULL };
typedef struct rg_open_opts {
    int backend;                /* enum rg_backend; NULL: do-nothing lines, real clock */
    const char *chip;           /* gpiod: overrides the rig file's chip; NULL: keep */
    const char *sim_log;        /* simulator: event log (written as a unique
                                   LOG.part.XXXXXX, renamed when the machine closes or
                                   stops; a device or FIFO in place: src/common/lm_out.h);
                                   NULL: none.  A log that lost a line (a write
                                   error) makes close return RG_EIO */
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
    volatile int32_t pump;              /* 1: a heartbeat pump gates the light; 0: none
                                           (the light follows the laser line) */
    volatile int32_t shutter, indicator;
} rg_sim_shared;
/* The scan planner (rg_scan.c, doc/scan-time.md): a scan's predicted machine time
 * from the rig's profiles, split by what set it.  Every move is the machine's own
 * coordinated trapezoid (rig_api.move_steps), so its time is the tightest joint's:
 * the one whose speed caps the cruise and the one whose acceleration caps the ramps. */
#define RG_SCAN_ORDER_MAX 20000
typedef struct rg_scan_stats {
    long n;                     /* targets */
    double t_total;             /* predicted: moves + settle + exposures (s) */
    double t_moves;             /* the profiles' durations, summed (s) */
    double t_ticks;             /* what the control step adds to them (DIR set-up
                                   tick, rounding to whole ticks) (s) */
    double t_settle;            /* settle_ms after every move (s) */
    double t_expose;            /* the exposures (s) */
    double t_speed[RG_NJOINTS]; /* cruise time each joint's speed set (s) */
    double t_accel[RG_NJOINTS]; /* ramp time each joint's acceleration set (s) */
    double path[RG_NJOINTS];    /* each joint's summed travel (steps) */
    const char *limit;          /* the largest single share, in words (static) */
} rg_scan_stats;
/* Exposure on the fly (rg_sweep.c, doc/scan-time.md): one continuous motion through
 * the targets, a short pulse as each is passed.  Per exposure: */
typedef struct rg_sweep_shot {
    double mean[RG_NJOINTS];    /* the motors' position during the pulse (steps: no
                                   motor steps while the light is on) */
#define RG_SWEEP_SAMPLES 8
    long at[RG_SWEEP_SAMPLES][RG_NJOINTS];  /* the same, as counted steps (at[0]) */
    int nat;                    /* entries in at[] (1) */
    double c_on[RG_NJOINTS], c_off[RG_NJOINTS]; /* the smooth commanded path (fractional
                                   steps) at the light's start and end: what shafts
                                   moving continuously, not in steps, would follow */
    double t_on;                /* machine clock at the laser's rise (s) */
} rg_sweep_shot;
typedef struct rg_sweep_stats {
    long n;                     /* targets */
    double t_total;             /* predicted: the move to the first target, its settle,
                                   the sweep, the last exposure, the final settle (s) */
    double t_sweep;             /* the continuous motion alone (s) */
    int lim_speed[RG_NJOINTS];  /* segments whose cruise each joint's speed capped */
    int lim_accel[RG_NJOINTS];  /* ... whose ramps each joint's acceleration capped */
    int lim_turn[RG_NJOINTS];   /* junctions whose speed each joint's turn capped */
    int lim_expose;             /* segments capped by one exposure each (no overlap) */
    double v_max[RG_NJOINTS];   /* fastest speed of each joint during an exposure
                                   (steps/s) */
} rg_sweep_stats;
/* The beam on the cornea and on the detector for the apex pose (rg_spots.c; a rig that
 * cannot reach the apex: the scan's first target that does, rg_spots.ref): the
 * laser's Gaussian beam (q parameter, the paraxial engine's px_beam) along the solved
 * path laser -> m1 -> m2 -> [focus lens] -> cornea apex -> detector plane, flat
 * mirrors, the cornea a convex mirror of its apex radius R (a thin lens of power
 * -2/R, on-axis: the oblique incidence's astigmatism is left out).  Lengths mm. */
#define RG_SPOTS_SCAN 2001      /* focal lengths scanned (log-spaced, each sign) */
/* The beam through one pose with the cornea's oblique incidence (rg_spotscan.c, doc/rig.md
 * "Oblique incidence"): the beam reaches the cornea round (flat mirrors, a thin round
 * lens); the cornea reflects it with the power matrix, in the reflected beam's section
 * (t: in the plane of incidence, s: across it), P = 2 [k_t / cos(theta), k_ts; k_ts,
 * k_s cos(theta)] (k_t, k_s the surface's normal curvatures along the plane of
 * incidence and across it, k_ts the twist; a sphere: Coddington's f_t = -(R/2)
 * cos(theta), f_s = -R / (2 cos(theta))).  A round beam times a symmetric P is a
 * simple astigmatic beam whose axes are P's eigenvectors: exact for every k_ts (psi
 * the axes' angle from the plane of incidence), each axis's q carried apart.  The
 * configured focus lens stays lens_at before the point the beam meets the cornea. */
typedef struct rg_spot_pose {
    rg_target target;           /* the target solved (apex: RG_T_ANGLES 0 0) */
    rg_pose pose;
    double path[4];             /* laser->m1, m1->m2, m2->cornea, cornea->detector plane */
    double theta;               /* incidence on the cornea (rad; rg_beam.inc3) */
    double k_t, k_s, k_ts;      /* cornea's normal curvatures along / across the plane of
                                   incidence, twist (1/mm; convex > 0) */
    double f_t, f_s;            /* the reflection's focal lengths along the beam's two
                                   axes (mm; convex: < 0); psi 0: Coddington's */
    double psi;                 /* the t axis's angle from the plane of incidence, toward
                                   the sagittal direction (rad, |psi| <= pi/4) */
    double w_cornea;            /* beam radius on the cornea (round) */
    double w_t, w_s;            /* 1/e^2 radii at the detector plane, the beam's section */
    double det_inc;             /* angle of the beam to the detector plane's normal (rad) */
    double foot_major, foot_minor;  /* the spot's 1/e^2 semi-axes in the detector plane */
    double foot_angle;          /* the major axis from the detector's x' axis (rad, in
                                   (-pi/2, pi/2]; x': rig +x across the plane's normal,
                                   y' = normal x x') */
    double sigma_major_um, sigma_minor_um;  /* the centroid's shot-noise limit along
                                   them: (axis/2)/sqrt(photons) (0: no dose); ABI 3:
                                   with this pose's photons (below) */
    /* ---- ABI 3: the cornea's Fresnel reflectance at this incidence (n 1.376) */
    double refl_s, refl_p;      /* |rs|^2, |rp|^2 */
    double s_frac;              /* the power's share in s (the laser's field carried by
                                   the ideal mirrors; 0.5 unpolarized) */
    double reflectance;         /* s_frac refl_s + (1 - s_frac) refl_p */
    double photons;             /* rg_spots.photons scaled by reflectance / its normal-
                                   incidence reflectance (0: no dose) */
} rg_spot_pose;
#define RG_SPOTS_POSES 200      /* the scan: targets besides the apex */
typedef struct rg_spots {
    double path[4];             /* laser->m1, m1->m2, m2->cornea, cornea->detector */
    double w0, waist_before_m1; /* the waist radius used and where it lies (mm) */
    int waist_from_diameter;    /* 1: no 'beam_waist': the waist is beam_diameter_mm / 2
                                   at the cornea (without the lens) */
    double m2, lambda_mm, R;
    double lens_f, lens_at;     /* the configured lens (lens_at 0: none) */
    double w_m1, w_m2, w_cornea, w_det;     /* 1/e^2 radii with the configured optics */
    double nolens_cornea, nolens_det;       /* the same without any lens */
    /* the scan: a lens at scan_at before the apex (the configured one's place, or
     * half the m2-cornea leg), focal lengths +-[scan_at/20, 1e5] mm; the one whose
     * larger radius (cornea or detector) is smallest */
    double scan_at, best_f, best_cornea, best_det;
    int best_is_none;           /* 1: no lens does better than every scanned one */
    /* the centroid's shot-noise limit on the detector: the longest single exposure
     * the dose allows (and max_on_ms), the photons the cornea reflects (Fresnel at
     * normal incidence, n 1.376) all detected, sigma = (w/2)/sqrt(N) per axis */
    int have_dose;              /* 0: the rig file has no laser_power_mw */
    double expose_ms, photons, reflectance, sigma_um, sigma_best_um;
    /* ---- ABI 2: the oblique incidence over a scan (the fields above: the apex pose at
     * normal incidence, unchanged).  The scan: the apex and RG_SPOTS_POSES targets of
     * the dialogue's sunflower spiral, height h_k = scan_h sqrt((k + 0.5)/n), meridian
     * k * 137.50776405 deg, scan_h the cornea's zone (R/2 when the zone is 0). */
    double scan_h;
    long scan_n, scan_bad;      /* poses computed; targets that did not solve (skipped) */
    rg_spot_pose apex;          /* the apex pose, oblique */
    rg_spot_pose big, small;    /* the poses of the largest and smallest footprint major
                                   axis on the detector */
    rg_spot_pose steep;         /* the pose of the largest incidence on the cornea */
    int ref_not_apex;           /* 1: the apex pose does not solve (a rig blind there):
                                   the fields above the ABI 2 line are for the pose of
                                   ref, the scan's first target that solves; apex stays
                                   zero and the scan does not count it */
    rg_target ref;              /* the pose those fields are for (apex: RG_T_ANGLES 0 0) */
    /* ---- ABI 3: the lens balanced over the whole scan (a lens at scan_at before the
     * point each pose's beam meets the cornea): the focal length whose worst pose --
     * the larger of the beam radius on the cornea and the detector spot's major
     * semi-axis, over every pose that solves -- is smallest; its worst figures and the
     * apex-model lens's (best_f) on the same scan */
    int scan_best_is_none;      /* 1: no lens does better over the scan than none */
    double scan_best_f, scan_best_cornea, scan_best_det;
    double apexlens_worst_cornea, apexlens_worst_det;
    rg_spot_pose dim;           /* the pose of the scan's lowest reflectance */
} rg_spots;
/* ==== end of the machine ========================================================= */


typedef struct rig_api {
    int abi;                                   /* RIG_ABI */
    const char *(*version)(void);
    /* ---- geometry ---- */
    /* Every geometry function is pure (no global state, thread-safe). */
    /* The example rig geometry (README "Rig geometry"): a conic cornea, m1 folding a
     * beam along -x, m2 on the stage plane z = -60, detector 20 deg off axis. */
    void (*geometry_default)(rg_geometry *g);
    /* Set one rig-file key (see the list above) from its words (argv[0] is the
     * key).  0: done; 1: not a geometry key; RG_EINVAL: bad value (message). */
    int (*geometry_key)(rg_geometry *g, int argc, const char *const *argv,
                        char *err, size_t errcap);
    /* Normalise vectors, check consistency (m2 on p2, axes not parallel, radii,
     * travel lo < hi, asphere count).  RG_OK or RG_EINVAL with a message. */
    int (*geometry_check)(rg_geometry *g, char *err, size_t errcap);
    /* Eye pose from rotations about x, y, z (rad, applied in that order) and the
     * apex position. */
    void (*eye_pose)(rg_cornea *c, double rx, double ry, double rz, const double at[3]);
    /* Joint names "m1a" "m1b" "u" "v" "m2a" "m2b" (NULL past RG_NJOINTS). */
    const char *(*joint_name)(int joint);

    /* Target to a point and outward normal on the placed cornea (rig frame).
     * RG_OK or RG_EUNREACH (off the cornea) with a message. */
    int (*cornea_point)(const rg_cornea *c, const rg_target *t, double p[3],
                        double n[3], char *err, size_t errcap);
    /* Backward solution (section 38): closed form, Newton on the exact model when a
     * mirror has an offset, then the diagnostics and the condition number.  opts may
     * be NULL.  RG_OK (warnings in s->diag), RG_EUNREACH or RG_ETRAVEL (message
     * names the reason; s->diag has the bits; s->pose is the best attempt). */
    int (*solve)(const rg_geometry *g, const rg_target *t, const rg_solve_opts *opts,
                 rg_solution *s, char *err, size_t errcap);
    /* Forward model of a pose (exact: offsets, finite mirrors, the placed cornea).
     * RG_OK or RG_EUNREACH (beam misses a mirror or the cornea: b->diag). */
    int (*forward)(const rg_geometry *g, const rg_pose *p, rg_beam *b,
                   char *err, size_t errcap);
    /* Normal of a gimbal at angles (a, b), and the angles for a normal (the solution
     * nearer the zero pose).  gimbal_angles: RG_OK or RG_EUNREACH. */
    void (*gimbal_normal)(const rg_gimbal *m, double a, double b, double n[3]);
    int (*gimbal_angles)(const rg_gimbal *m, const double n[3], double *a, double *b);
    /* Jacobian of the spot (2 tangent coordinates on the cornea at the spot, 2 on the
     * detector plane, mm) with respect to the joints (rad, mm), row-major 4 x 6, and
     * the condition number of the map after scaling each joint by one step
     * (column-equilibrated when a joint is continuous).  RG_OK or RG_EUNREACH. */
    int (*jacobian)(const rg_geometry *g, const rg_pose *p, double J[4 * RG_NJOINTS],
                    double *cond, char *err, size_t errcap);
    /* Quantise a solution to the joints' steps (stage first, angles re-solved for
     * the quantised centre, then angles) and measure its landing errors. */
    int (*quantise)(const rg_geometry *g, const rg_target *t, const rg_solution *s,
                    rg_quantised *q, char *err, size_t errcap);
    /* Independent check through the trace engine: mirrors as TRACE_MIRROR planes, the
     * cornea as a TRACE_AXIAL surface with Fresnel reflection (a biconic: its
     * tangent plane where the forward model's beam meets it), a detector disc at
     * the detector point.
     * target: the point the beam should hit (a solution's target).  RG_OK (v
     * filled; v->hit 0 when the traced beam never reached the detector) or RG_EIO
     * (the trace engine failed: message). */
    int (*verify)(const struct trace_api *tr, const rg_geometry *g, const rg_pose *p,
                  const double target[3], rg_verify *v, char *err, size_t errcap);
    /* One line naming each RG_D_* bit set in diag ("m2 blocks the detector ray; ..."),
     * written to buf; returns buf. */
    const char *(*diag_text)(unsigned diag, char *buf, size_t cap);
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
    /* The move's profile without moving: its duration (s); RG_ETRAVEL as move. */
    int (*plan_move)(const rg_rig *rig, const long from[RG_NJOINTS],
                     const long to[RG_NJOINTS], double *seconds, char *err, size_t cap);
    int (*move_steps)(rg_machine *m, const long steps[RG_NJOINTS], rg_stop_fn stop,
                      void *ctx, char *err, size_t cap);
    /* Laser on for ms (<= max_on_ms), only with the interlock closed and every axis
     * at rest; off within one control step when the interlock opens (RG_EINTERLOCK). */
    int (*expose)(rg_machine *m, double ms, rg_stop_fn stop, void *ctx, char *err,
                  size_t cap);
    void (*position)(const rg_machine *m, long steps[RG_NJOINTS], rg_pose *p);
    /* Where the motors really are: 1 on the simulator (its motor model), 0 where the
     * chip has no feedback (steps then hold the commanded position). */
    int (*motors)(const rg_machine *m, long steps[RG_NJOINTS]);
    int (*homed)(const rg_machine *m);
    void (*timing)(const rg_machine *m, rg_timing *t);
    /* Laser off, then drivers disabled, lines released, log closed: 0 or RG_EIO. */
    int (*close)(rg_machine *m);
    /* Async-signal-safe: every open machine's laser off, then its drivers disabled
     * (and the simulator's log completed).  For a signal handler or stop hook. */
    void (*emergency_off)(void);
    /* ---- safety (doc/rig-safety.md) ---- */
    /* The latched fault: its cause (RG_F_*; 0 none) and why, with when (sim time). */
    int (*fault)(const rg_machine *m, char *why, size_t cap);
    /* Clear the latch: RG_OK, or RG_EFAULT while its cause persists (interlock open,
     * limit switch tripped, key off).  Homing is still required after a fault that
     * found the drivers enabled (their current cut: position not held). */
    int (*reset)(rg_machine *m, char *err, size_t cap);
    /* The dose of the session so far plus n exposures of ms: RG_OK, RG_EDOSE (over
     * the limit: message with the fraction) or RG_EINVAL (no dose keys, a
     * wavelength outside 400-700 nm).  d filled in every case it can be. */
    int (*dose_plan)(const rg_machine *m, double ms, long n, rg_dose *d, char *err,
                     size_t cap);
    /* The same from a rig alone (no session). */
    int (*dose_rig)(const rg_rig *rig, double ms, long n, rg_dose *d, char *err,
                    size_t cap);
    /* MPE at the cornea (J/m^2) for a small source, wavelength nm, duration s: IEC
     * 60825-1:2014 Table A.1 (see rg_dose.c); NAN outside 400-700 nm or t < 18 us. */
    double (*mpe)(double wavelength_nm, double t, const char **limit);
    /* ---- the scan planner (doc/scan-time.md) ---- */
    /* Order n targets (steps: n rows of RG_NJOINTS step counts, e.g. from
     * quantise) to shorten the machine's time from start: greedy nearest neighbour
     * by the move's own duration (rig_api.plan_move's profile), then 2-opt until no
     * reversal gains; deterministic (ties: the lower index).  order[0..n-1] gets a
     * permutation of 0..n-1.  The work is O(n^2): above 2048 targets the nearest
     * neighbour alone, above RG_SCAN_ORDER_MAX the given order (identity).  RG_OK,
     * RG_ETRAVEL (a target outside travel, before anything is ordered) or RG_EINVAL /
     * RG_ENOMEM. */
    int (*scan_order)(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps,
                      long n, long *order, char *err, size_t cap);
    /* The predicted time of visiting the targets in order (NULL: as given) from start,
     * a settle after every move and an exposure of expose_ms at every target; st
     * filled (st->limit names what limits it).  RG_OK or RG_ETRAVEL. */
    int (*scan_time)(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps,
                     const long *order, long n, double expose_ms, rg_scan_stats *st,
                     char *err, size_t cap);
    /* One line saying where the time goes (the shares above 5 %), into buf. */
    const char *(*scan_limit_text)(const rg_scan_stats *st, char *buf, size_t cap);
    /* The machine's clock (s): simulated time on the simulator, the real clock on
     * a chip. */
    double (*clock_s)(const rg_machine *m);
    /* ---- exposure on the fly (rg_sweep.c, doc/scan-time.md) ---- */
    /* Visit n targets (rows of step counts) in the given order in one continuous
     * motion and fire a pulse of expose_ms at each: a normal move to the first, then
     * one profile through them all that slows for each turn (a joint's velocity jump
     * at a target at most half its acceleration times the leg's duration) and ramps
     * within half the acceleration, never faster than each joint's speed nor than one
     * exposure per leg.  The pulse must fit in half a control step: it sits in the
     * step's low half, after its STEP edges, so no motor steps while the light is on
     * (the simulator's check stays on).  Needs 'expose_moving yes' and shutter_ms 0;
     * every other check of move_steps and expose holds: travel and the session's
     * dose for all n before the first pulse, interlock and limits every control step,
     * the key switch and the heartbeat at every pulse, lateness, lost steps.
     * shot[k] gets pulse k's motor position and time (may be NULL).  RG_OK,
     * RG_EINVAL (not allowed: why), RG_ETRAVEL, RG_EDOSE, a fault's code, RG_ESTOP. */
    int (*sweep)(rg_machine *m, const long *steps, long n, double expose_ms, rg_stop_fn stop,
                 void *ctx, rg_sweep_shot *shot, char *err, size_t cap);
    /* The same sweep's predicted time from start and what capped it (no machine). */
    int (*sweep_time)(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps,
                      long n, double expose_ms, rg_sweep_stats *st, char *err, size_t cap);
    /* ---- the beam (rg_spots.c) ---- */
    /* The beam radius on the cornea and the detector for the apex pose, the focus
     * lens that balances them and the centroid's shot-noise limit; then (ABI 2) the
     * oblique incidence over the scan (rg_spots.apex, big, small, steep).  A rig that
     * cannot reach the apex: its first scan target that solves (ref_not_apex).  RG_OK,
     * or RG_EINVAL ("FILE:LINE: why" for a rig-file value the geometry rules out; no
     * wavelength; no pose of the scan solves). */
    int (*spots)(const rg_rig *rig, rg_spots *s, char *err, size_t cap);
    /* ---- ABI 2: the cornea's oblique incidence (rg_spotscan.c, rg_cornea.c) ---- */
    /* The placed cornea's second fundamental form at rig point p (on the surface) on
     * the unit tangent vectors e1, e2 (rig frame): K[0] = k(e1), K[1] = k(e2), K[2] =
     * II(e1, e2) (1/mm; convex > 0; analytic second derivatives of the sag).  RG_OK or
     * RG_EUNREACH (off the surface). */
    int (*cornea_curvature)(const rg_cornea *c, const double p[3], const double e1[3],
                            const double e2[3], double K[3]);
    /* The beam along path (as rg_spot_pose.path) with the laser, lens and photons of s
     * (from spots), a cornea of curvatures k_t, k_s, k_ts met at incidence theta: fills
     * p's path, theta, k_*, f_t, f_s, psi, w_cornea, w_t, w_s (the rest untouched).
     * theta 0, k_t = k_s = 1/R, k_ts 0 is the apex model of spots: w_t = w_s = w_det
     * exactly.  RG_OK or RG_EINVAL (the lens off the leg, not a beam). */
    int (*spot_chain)(const rg_spots *s, const double path[4], double theta, double k_t,
                      double k_s, double k_ts, rg_spot_pose *p, char *err, size_t cap);
    /* One target's pose solved and its beam (all of p).  RG_OK, RG_EUNREACH (the
     * target does not solve, or its beam misses the detector plane), RG_EINVAL. */
    int (*spot_pose)(const rg_rig *rig, const rg_spots *s, const rg_target *t,
                     rg_spot_pose *p, char *err, size_t cap);
} rig_api;

typedef const rig_api *(*rig_get_api_fn)(int abi);
const rig_api *rig_get_api(int abi);

#endif
