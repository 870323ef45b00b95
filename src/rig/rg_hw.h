/* rg_hw.h -- inside the machine part of the rig engine (not public): the chip
 * interface both backends implement (rg_sim.c, rg_gpiod.c, rg_null in rg_sim.c), the
 * machine state shared by motion (rg_motion.c) and safety (rg_safety.c), and the
 * geometry half reached through its table. */
#ifndef RG_HW_H
#define RG_HW_H
#include <stdint.h>
#include "rig/rg_int.h"

/* Output groups: each is one bulk request, so one call changes all its lines (all
 * STEP lines together).  Bit j of a mask or value is axis j (RG_J_*); LASER and
 * HEART have bit 0 only.  Values are logical: 1 = active (active-low applied by the
 * backend). */
enum { RG_G_STEP, RG_G_DIR, RG_G_ENABLE, RG_G_LASER, RG_G_HEART, RG_G_SHUTTER,
       RG_G_INDICATOR, RG_NGROUPS };
/* Inputs: bit j = home switch of axis j is active (tripped); RG_IN_INTERLOCK = closed;
 * RG_IN_LIMIT(j) = the limit switch of axis j tripped; RG_IN_KEY = key switch on. */
#define RG_IN_INTERLOCK (1u << RG_NJOINTS)
#define RG_IN_LIMIT(j) (1u << (RG_NJOINTS + 1 + (j)))
#define RG_IN_LIMITS (((1u << RG_NJOINTS) - 1) << (RG_NJOINTS + 1))
#define RG_IN_KEY (1u << (2 * RG_NJOINTS + 1))
#define RG_NINPUTS (2 * RG_NJOINTS + 2)

typedef struct rg_chip rg_chip;
typedef struct rg_chip_ops {
    /* Set the lines of group g whose bits are in mask to the bits of val. */
    int  (*set)(rg_chip *c, int g, unsigned mask, unsigned val);
    /* Current input levels, and the inputs that changed (an edge event) since the
     * last call: a short opening of the interlock is seen even if closed again. */
    int  (*inputs)(rg_chip *c, unsigned *level, unsigned *edges);
    int64_t (*now)(rg_chip *c);                 /* ns */
    void (*sleep_until)(rg_chip *c, int64_t t); /* absolute deadline, ns */
    /* Async-signal-safe: laser inactive, then every ENABLE inactive. */
    void (*emergency)(rg_chip *c);
    /* Release everything (after the caller switched laser and drivers off). */
    int (*close)(rg_chip *c);       /* 0, or RG_EIO: a simulator's log lost lines */
    /* Moves and exposures tell the simulator what they do (log lines); may be NULL. */
    void (*note)(rg_chip *c, const char *what);
    /* The motors' positions where the chip knows them (simulator): 1, else 0. */
    int  (*motors)(rg_chip *c, long steps[RG_NJOINTS]);
} rg_chip_ops;
struct rg_chip { const rg_chip_ops *ops; };

int rg_sim_open(const rg_rig *rig, const rg_open_opts *o, rg_chip **c, char *err,
                size_t cap);
int rg_null_open(const rg_rig *rig, rg_chip **c, char *err, size_t cap);
int rg_gpiod_open(const rg_rig *rig, const char *chip, rg_chip **c, char *err,
                  size_t cap);

#define RG_TIMING_MAX 65536     /* lateness samples kept (a ring) */
struct rg_machine {
    const rg_rig *rig_ptr;
    rg_rig rig;
    rg_chip *chip;
    long pos[RG_NJOINTS];       /* commanded position, steps */
    int homed;
    unsigned dir_val;           /* last DIR values written */
    int laser_on;
    char sched[160];            /* what real-time scheduling got */
    /* step-edge lateness (real clock backends) */
    long late_n;
    float *late;                /* RG_TIMING_MAX samples, us */
    int measure;                /* 1: record lateness */
    struct rg_machine *next;    /* the list emergency_off walks */
    /* the latch (rg_safety.c) */
    int fault;                  /* RG_F_*; 0: none */
    char fault_why[RG_ERRMAX];
    int drivers_on;             /* ENABLE lines active (set by homing) */
    int64_t last_rise;          /* last STEP falling edge (chip clock): the low time */
    /* the session's dose (rg_dose.c) */
    long dose_n;
    double dose_t;              /* summed on-time, s */
};

/* rg_motion.c */
int  rg_pose_steps(const rg_rig *rig, const rg_pose *p, long steps[RG_NJOINTS], char *err,
                   size_t cap);
int  rg_move_steps(rg_machine *m, const long target[RG_NJOINTS], rg_stop_fn stop, void *ctx,
                   char *err, size_t cap);
int  rg_move(rg_machine *m, const rg_pose *p, rg_stop_fn stop, void *ctx, char *err,
             size_t cap);
int  rg_home(rg_machine *m, rg_stop_fn stop, void *ctx, char *err, size_t cap);
void rg_position(const rg_machine *m, long steps[RG_NJOINTS], rg_pose *p);
int64_t rg_tick_ns(const rg_rig *rig);
int  rg_plan_move(const rg_rig *rig, const long from[RG_NJOINTS], const long to[RG_NJOINTS],
                  double *seconds, char *err, size_t cap);
double rg_move_time(const rg_rig *rig, const long from[RG_NJOINTS], const long to[RG_NJOINTS],
                    int *vj, int *aj, double *t_acc, double *t_cruise);
/* rg_scan.c */
int  rg_scan_order(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps, long n,
                   long *order, char *err, size_t cap);
int  rg_scan_time(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps,
                  const long *order, long n, double expose_ms, rg_scan_stats *st, char *err,
                  size_t cap);
const char *rg_scan_limit_text(const rg_scan_stats *st, char *buf, size_t cap);
/* every target (n rows of RG_NJOINTS steps) within its axis's travel: 0, or
 * RG_ETRAVEL with the first one outside named in err (rg_scan.c, rg_sweep.c) */
int  rg_check_targets(const rg_rig *rig, const long *steps, long n, char *err, size_t cap);
void rg_wait(rg_machine *m, int64_t deadline);  /* sleep_until + lateness record */
int  rg_pulse(rg_machine *m, unsigned mask, int64_t at, int64_t tick, char *err, size_t cap);
int  rg_settle(rg_machine *m, char *err, size_t cap);
int  rg_lost_steps(rg_machine *m, char *err, size_t cap);
/* rg_sweep.c */
int  rg_sweep(rg_machine *m, const long *steps, long n, double expose_ms, rg_stop_fn stop,
              void *ctx, rg_sweep_shot *shot, char *err, size_t cap);
int  rg_sweep_time(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps, long n,
                   double expose_ms, rg_sweep_stats *st, char *err, size_t cap);
/* rg_safety.c */
int  rg_open(const rg_rig *rig, const rg_open_opts *o, rg_machine **m, char *err,
             size_t cap);
int  rg_close(rg_machine *m);
int  rg_expose(rg_machine *m, double ms, rg_stop_fn stop, void *ctx, char *err,
               size_t cap);
void rg_emergency_off(void);
void rg_laser_off(rg_machine *m);
void rg_get_timing(const rg_machine *m, rg_timing *t);
const char *rg_sched_note(const rg_machine *m);
int  rg_latch(rg_machine *m, int cause, int rc, char *err, size_t cap, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
int  rg_latched(rg_machine *m, char *err, size_t cap);      /* RG_EFAULT if latched */
int  rg_guard(rg_machine *m, int moving, char *err, size_t cap);
int  rg_fault_get(const rg_machine *m, char *why, size_t cap);
int  rg_reset(rg_machine *m, char *err, size_t cap);
/* rg_dose.c */
double rg_mpe(double wavelength_nm, double t, const char **limit);
int  rg_dose_rig(const rg_rig *rig, double ms, long n, rg_dose *d, char *err, size_t cap);
int  rg_dose_plan(const rg_machine *m, double ms, long n, rg_dose *d, char *err, size_t cap);
/* rg_spots.c */
#define RG_N_CORNEA 1.376       /* Gullstrand's cornea: its Fresnel reflectance */
int  rg_spots_run(const rg_rig *rig, rg_spots *s, char *err, size_t cap);
struct px_beam;
/* The laser's beam to the cornea along path with a lens f at `at` before it (0: none). */
int  rg_spots_to_cornea(const rg_spots *s, const double path[4], double f, double at,
                        struct px_beam *b, double w[3]);
/* rg_spotscan.c: the cornea's oblique incidence (rig_api.spot_chain, spot_pose) and the
 * scan's extremes in s (called by rg_spots_run once the apex figures are in). */
int  rg_spot_chain(const rg_spots *s, const double path[4], double theta, double k_t,
                   double k_s, double k_ts, rg_spot_pose *p, char *err, size_t cap);
int  rg_spot_pose_run(const rg_rig *rig, const rg_spots *s, const rg_target *t,
                  rg_spot_pose *p, char *err, size_t cap);
int  rg_spots_scan(const rg_rig *rig, rg_spots *s, char *err, size_t cap);
/* The scan's k-th target (0 <= k < RG_SPOTS_POSES) and its largest height. */
rg_target rg_spots_target(const rg_rig *rig, int k);
double rg_spots_height(const rg_rig *rig);
/* rg_file.c */
int  rg_rig_load(const char *path, rg_rig *rig, char *err, size_t cap);
int  rg_rig_parse(const char *text, size_t len, const char *name, rg_rig *rig, char *err,
                  size_t cap);
/* The geometry half's table (rig_get_api): its rig-file keys, default and check. */
const rig_api *rg_geom_api(void);

#endif
