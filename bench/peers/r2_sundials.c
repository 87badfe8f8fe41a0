/*
 * r2_sundials.c -- SUNDIALS (6.4.1, Debian bookworm libsundials-dev) peer for
 * reference problem R2 of docs/theory.md: N identical pendulums in a
 * row between two walls, exponential contact law, harmonic base acceleration.
 *
 * Usage:
 *   r2_sundials METHOD N OMEGA_OVER_OMEGA0 PERIODS RTOL ATOL REPEATS
 *
 * METHOD:
 *   cvode-adams         CVODE, Adams-Moulton (orders 1..12), fixed-point
 *                       nonlinear iteration (the usual non-stiff setup)
 *   cvode-adams-newton  CVODE, Adams-Moulton, Newton + band direct solver
 *   cvode-bdf           CVODE, BDF (orders 1..5), Newton + band direct solver
 *                       (difference-quotient band Jacobian, mu = 2, ml = 3)
 *   arkode-dp5          ERKStep, ARKODE_DORMAND_PRINCE_7_4_5 (5(4), FSAL)
 *   arkode-verner8      ARKStep explicit-only, ARKODE_VERNER_8_5_6
 *                       (8 stages, order 6, embedding 5)
 *   arkode-fehlberg8    ARKStep explicit-only, ARKODE_FEHLBERG_13_7_8
 *                       (13 stages, order 8, embedding 7)
 *   arkode-erk-default  ERKStep with no table set (default order 4:
 *                       ARKODE_ZONNEVELD_5_3_4)
 *   erkstep-verner8-raw, erkstep-fehlberg8-raw
 *                       the same two tables through ERKStep; SUNDIALS <= 6.6.2
 *                       treats any table with c_s = 1 as FSAL (upstream issue
 *                       #311, fixed in 6.7.0), so these give WRONG results.
 *                       Kept only to demonstrate the quirk.
 *
 * Environment overrides (for checks only; defaults are R2 exactly):
 *   R2_GAP         every clearance g in metres (default 1e-3; 1e3 = linear limit)
 *   R2_FIXED_STEP  if set (> 0), ERKStep/ARKStep methods take fixed steps of
 *                  this size, no error control (used to verify the order of
 *                  the Butcher tables and the issue #311 quirk)
 *
 * Output: one JSON line on stdout. "seconds" is the best wall time
 * (CLOCK_MONOTONIC) over REPEATS runs of the integration call only (solver
 * creation/setup and output are excluded). Counters are from the last run
 * (runs are deterministic). Non-zero exit and a JSON line with "error" on
 * failure.
 *
 * Internal state layout is interleaved, y = (u1, v1, u2, v2, ...), so that the
 * Jacobian is banded; "final_state" is printed as (u1..uN, v1..vN).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_version.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

/* ---- R2 parameters (docs/theory.md §6) ---- */
#define R2_M      0.227      /* kg */
#define R2_OMEGA0 7.41       /* rad/s */
#define R2_ZETA   0.013
#define R2_A      0.05       /* m/s^2, base acceleration amplitude */
#define R2_GAP    1.0e-3     /* m, every clearance */
#define R2_CA     1.0        /* N, a */
#define R2_CB     (1.0 / 1.2) /* N s/m, b = a / 1.2 */
#define R2_ALPHA  1.3e5      /* 1/m */

typedef struct {
  long n;           /* number of bodies */
  double k, c, m;   /* stiffness, damping, mass */
  double inv_m;
  double A, Omega;  /* base acceleration amplitude, frequency */
  double g;         /* clearance */
  double hfixed;    /* > 0: fixed step for ARKODE methods (checks only) */
  double a, b, alpha;
  long nrhs;        /* rhs calls (own counter, includes DQ Jacobian calls) */
} Problem;

/* Right-hand side. y = (u1, v1, ..., uN, vN). Allocation-free; every contact's
 * exponential is evaluated on every call. */
static int rhs(realtype t, N_Vector yv, N_Vector ydotv, void *user_data)
{
  Problem *p = (Problem *)user_data;
  const double *y = N_VGetArrayPointer(yv);
  double *yd = N_VGetArrayPointer(ydotv);
  const long n = p->n;
  const double k = p->k, c = p->c, m = p->m, inv_m = p->inv_m;
  const double g = p->g, a = p->a, b = p->b, alpha = p->alpha;
  const double base = -m * p->A * sin(p->Omega * t);
  long i;
  double s, sd, F;

  p->nrhs++;

  /* accumulate forces on body i in yd[2i+1] */
  for (i = 0; i < n; i++) {
    const double u = y[2 * i], v = y[2 * i + 1];
    yd[2 * i] = v;
    yd[2 * i + 1] = -c * v - k * u + base;
  }
  /* contact 0: left wall with body 1 */
  s = -y[0] - g;
  sd = -y[1];
  F = (a + b * sd) * exp(alpha * s);
  yd[1] += F;
  /* contacts j = 1..N-1 between bodies j and j+1 (0-based i = j-1, i+1) */
  for (i = 0; i + 1 < n; i++) {
    s = y[2 * i] - y[2 * i + 2] - g;
    sd = y[2 * i + 1] - y[2 * i + 3];
    F = (a + b * sd) * exp(alpha * s);
    yd[2 * i + 1] -= F;
    yd[2 * i + 3] += F;
  }
  /* contact N: body N with right wall */
  s = y[2 * (n - 1)] - g;
  sd = y[2 * (n - 1) + 1];
  F = (a + b * sd) * exp(alpha * s);
  yd[2 * (n - 1) + 1] -= F;

  for (i = 0; i < n; i++) yd[2 * i + 1] *= inv_m;
  return 0;
}

static double now_seconds(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

enum Kind {
  K_CVODE_ADAMS, K_CVODE_ADAMS_NEWTON, K_CVODE_BDF, K_ERK_TABLE, K_ARK_TABLE,
  K_ERK_DEFAULT
};

typedef struct {
  const char *name;
  enum Kind kind;
  int table;           /* ARKODE_ERKTableID for table kinds */
  const char *descr;
} Method;

static const Method METHODS[] = {
  {"cvode-adams", K_CVODE_ADAMS, -1, "CVODE Adams, fixed-point iteration"},
  {"cvode-adams-newton", K_CVODE_ADAMS_NEWTON, -1, "CVODE Adams, Newton + band LU (DQ Jacobian)"},
  {"cvode-bdf", K_CVODE_BDF, -1, "CVODE BDF, Newton + band LU (DQ Jacobian)"},
  {"arkode-dp5", K_ERK_TABLE, ARKODE_DORMAND_PRINCE_7_4_5, "ERKStep ARKODE_DORMAND_PRINCE_7_4_5"},
  {"arkode-verner8", K_ARK_TABLE, ARKODE_VERNER_8_5_6, "ARKStep explicit-only ARKODE_VERNER_8_5_6"},
  {"arkode-fehlberg8", K_ARK_TABLE, ARKODE_FEHLBERG_13_7_8, "ARKStep explicit-only ARKODE_FEHLBERG_13_7_8"},
  {"arkode-erk-default", K_ERK_DEFAULT, -1, "ERKStep default table (order 4, ARKODE_ZONNEVELD_5_3_4)"},
  {"erkstep-verner8-raw", K_ERK_TABLE, ARKODE_VERNER_8_5_6, "ERKStep ARKODE_VERNER_8_5_6 (affected by SUNDIALS issue #311)"},
  {"erkstep-fehlberg8-raw", K_ERK_TABLE, ARKODE_FEHLBERG_13_7_8, "ERKStep ARKODE_FEHLBERG_13_7_8 (affected by SUNDIALS issue #311)"},
};

static void fail(const char *method, const char *what, int flag)
{
  printf("{\"method\":\"%s\",\"error\":\"%s\",\"flag\":%d}\n", method, what, flag);
  fflush(stdout);
  exit(1);
}

#define CHECK(call, what)                                   \
  do {                                                      \
    int flag_ = (call);                                     \
    if (flag_ < 0) fail(meth->name, what, flag_);           \
  } while (0)

typedef struct {
  double seconds;
  long steps, attempts, nrhs, nrhs_solver, err_fails, lin_setups, jac_evals,
      nl_iters, nl_fails;
  double tret;
} RunStats;

/* One full run: setup (untimed), integrate (timed), collect stats, copy state
 * into out (interleaved layout). */
static void run_once(const Method *meth, Problem *prob, double t_end, double rtol,
                     double abstol, RunStats *st, double *out)
{
  SUNContext ctx = NULL;
  N_Vector y;
  void *mem = NULL;
  SUNMatrix J = NULL;
  SUNLinearSolver LS = NULL;
  SUNNonlinearSolver NLS = NULL;
  const sunindextype neq = 2 * prob->n;
  realtype tret = 0.0;
  double t0w = 0.0, t1w = 0.0;
  long i;
  const long maxsteps = 10000000L;

  if (SUNContext_Create(NULL, &ctx) != 0) fail(meth->name, "SUNContext_Create", -1);
  y = N_VNew_Serial(neq, ctx);
  if (y == NULL) fail(meth->name, "N_VNew_Serial", -1);
  N_VConst(0.0, y); /* start at rest */
  prob->nrhs = 0;
  memset(st, 0, sizeof(*st));

  switch (meth->kind) {
  case K_CVODE_ADAMS:
  case K_CVODE_ADAMS_NEWTON:
  case K_CVODE_BDF:
    mem = CVodeCreate(meth->kind == K_CVODE_BDF ? CV_BDF : CV_ADAMS, ctx);
    if (mem == NULL) fail(meth->name, "CVodeCreate", -1);
    CHECK(CVodeInit(mem, rhs, 0.0, y), "CVodeInit");
    CHECK(CVodeSetUserData(mem, prob), "CVodeSetUserData");
    CHECK(CVodeSStolerances(mem, rtol, abstol), "CVodeSStolerances");
    CHECK(CVodeSetMaxNumSteps(mem, maxsteps), "CVodeSetMaxNumSteps");
    CHECK(CVodeSetStopTime(mem, t_end), "CVodeSetStopTime");
    if (meth->kind == K_CVODE_ADAMS) {
      NLS = SUNNonlinSol_FixedPoint(y, 0, ctx);
      if (NLS == NULL) fail(meth->name, "SUNNonlinSol_FixedPoint", -1);
      CHECK(CVodeSetNonlinearSolver(mem, NLS), "CVodeSetNonlinearSolver");
    } else {
      J = SUNBandMatrix(neq, 2, 3, ctx);
      LS = SUNLinSol_Band(y, J, ctx);
      if (J == NULL || LS == NULL) fail(meth->name, "band matrix/solver", -1);
      CHECK(CVodeSetLinearSolver(mem, LS, J), "CVodeSetLinearSolver");
    }
    t0w = now_seconds();
    CHECK(CVode(mem, t_end, y, &tret, CV_NORMAL), "CVode");
    t1w = now_seconds();
    CVodeGetNumSteps(mem, &st->steps);
    CVodeGetNumRhsEvals(mem, &st->nrhs_solver);
    CVodeGetNumErrTestFails(mem, &st->err_fails);
    CVodeGetNumNonlinSolvIters(mem, &st->nl_iters);
    CVodeGetNumNonlinSolvConvFails(mem, &st->nl_fails);
    if (meth->kind != K_CVODE_ADAMS) {
      long nfeLS = 0;
      CVodeGetNumLinSolvSetups(mem, &st->lin_setups);
      CVodeGetNumJacEvals(mem, &st->jac_evals);
      CVodeGetNumLinRhsEvals(mem, &nfeLS);
      st->nrhs_solver += nfeLS;
    }
    st->attempts = st->steps + st->err_fails + st->nl_fails;
    CVodeFree(&mem);
    break;

  case K_ERK_TABLE:
  case K_ERK_DEFAULT:
    mem = ERKStepCreate(rhs, 0.0, y, ctx);
    if (mem == NULL) fail(meth->name, "ERKStepCreate", -1);
    CHECK(ERKStepSetUserData(mem, prob), "ERKStepSetUserData");
    CHECK(ERKStepSStolerances(mem, rtol, abstol), "ERKStepSStolerances");
    if (meth->kind == K_ERK_TABLE)
      CHECK(ERKStepSetTableNum(mem, (ARKODE_ERKTableID)meth->table), "ERKStepSetTableNum");
    CHECK(ERKStepSetMaxNumSteps(mem, maxsteps), "ERKStepSetMaxNumSteps");
    CHECK(ERKStepSetStopTime(mem, t_end), "ERKStepSetStopTime");
    if (prob->hfixed > 0) CHECK(ERKStepSetFixedStep(mem, prob->hfixed), "ERKStepSetFixedStep");
    t0w = now_seconds();
    CHECK(ERKStepEvolve(mem, t_end, y, &tret, ARK_NORMAL), "ERKStepEvolve");
    t1w = now_seconds();
    ERKStepGetNumSteps(mem, &st->steps);
    ERKStepGetNumStepAttempts(mem, &st->attempts);
    ERKStepGetNumRhsEvals(mem, &st->nrhs_solver);
    ERKStepGetNumErrTestFails(mem, &st->err_fails);
    ERKStepFree(&mem);
    break;

  case K_ARK_TABLE: {
    long nfi = 0;
    mem = ARKStepCreate(rhs, NULL, 0.0, y, ctx); /* explicit only */
    if (mem == NULL) fail(meth->name, "ARKStepCreate", -1);
    CHECK(ARKStepSetUserData(mem, prob), "ARKStepSetUserData");
    CHECK(ARKStepSStolerances(mem, rtol, abstol), "ARKStepSStolerances");
    CHECK(ARKStepSetTableNum(mem, ARKODE_DIRK_NONE, (ARKODE_ERKTableID)meth->table),
          "ARKStepSetTableNum");
    CHECK(ARKStepSetMaxNumSteps(mem, maxsteps), "ARKStepSetMaxNumSteps");
    CHECK(ARKStepSetStopTime(mem, t_end), "ARKStepSetStopTime");
    if (prob->hfixed > 0) CHECK(ARKStepSetFixedStep(mem, prob->hfixed), "ARKStepSetFixedStep");
    t0w = now_seconds();
    CHECK(ARKStepEvolve(mem, t_end, y, &tret, ARK_NORMAL), "ARKStepEvolve");
    t1w = now_seconds();
    ARKStepGetNumSteps(mem, &st->steps);
    ARKStepGetNumStepAttempts(mem, &st->attempts);
    ARKStepGetNumRhsEvals(mem, &st->nrhs_solver, &nfi);
    ARKStepGetNumErrTestFails(mem, &st->err_fails);
    ARKStepFree(&mem);
    break;
  }
  }

  st->seconds = t1w - t0w;
  st->nrhs = prob->nrhs;
  st->tret = tret;
  if (fabs(tret - t_end) > 1e-12 * fabs(t_end))
    fail(meth->name, "integration did not reach t_end", -1);
  {
    const double *yy = N_VGetArrayPointer(y);
    for (i = 0; i < neq; i++) out[i] = yy[i];
  }
  if (NLS) SUNNonlinSolFree(NLS);
  if (LS) SUNLinSolFree(LS);
  if (J) SUNMatDestroy(J);
  N_VDestroy(y);
  SUNContext_Free(&ctx);
}

int main(int argc, char **argv)
{
  const Method *meth = NULL;
  Problem prob;
  long n, repeats, r, i;
  double ratio, periods, rtol, abstol, T, t_end, best = INFINITY;
  double *state;
  RunStats st;
  char version[64];
  const char *env;
  size_t mi;

  if (argc != 8) {
    fprintf(stderr,
            "usage: %s METHOD N OMEGA_OVER_OMEGA0 PERIODS RTOL ATOL REPEATS\n"
            "methods:",
            argv[0]);
    for (mi = 0; mi < sizeof(METHODS) / sizeof(METHODS[0]); mi++)
      fprintf(stderr, " %s", METHODS[mi].name);
    fprintf(stderr, "\n");
    return 2;
  }
  for (mi = 0; mi < sizeof(METHODS) / sizeof(METHODS[0]); mi++)
    if (strcmp(argv[1], METHODS[mi].name) == 0) meth = &METHODS[mi];
  if (meth == NULL) {
    fprintf(stderr, "unknown method '%s'\n", argv[1]);
    return 2;
  }
  n = strtol(argv[2], NULL, 10);
  ratio = atof(argv[3]);
  periods = atof(argv[4]);
  rtol = atof(argv[5]);
  abstol = atof(argv[6]);
  repeats = strtol(argv[7], NULL, 10);
  if (n < 1 || ratio <= 0 || periods <= 0 || rtol <= 0 || abstol <= 0 || repeats < 1) {
    fprintf(stderr, "invalid arguments\n");
    return 2;
  }

  prob.n = n;
  prob.m = R2_M;
  prob.inv_m = 1.0 / R2_M;
  prob.k = R2_M * R2_OMEGA0 * R2_OMEGA0;
  prob.c = 2.0 * R2_ZETA * R2_M * R2_OMEGA0;
  prob.A = R2_A;
  prob.Omega = ratio * R2_OMEGA0;
  prob.g = R2_GAP;
  prob.a = R2_CA;
  prob.b = R2_CB;
  prob.alpha = R2_ALPHA;
  env = getenv("R2_GAP");
  if (env != NULL && *env) prob.g = atof(env);
  prob.hfixed = 0.0;
  env = getenv("R2_FIXED_STEP");
  if (env != NULL && *env) prob.hfixed = atof(env);

  T = 2.0 * M_PI / prob.Omega;
  t_end = periods * T;

  state = (double *)malloc(sizeof(double) * 2 * n);
  if (state == NULL) fail(meth->name, "malloc", -1);

  for (r = 0; r < repeats; r++) {
    run_once(meth, &prob, t_end, rtol, abstol, &st, state);
    if (st.seconds < best) best = st.seconds;
  }

  SUNDIALSGetVersion(version, sizeof(version));
  printf("{\"method\":\"%s\",\"solver\":\"SUNDIALS %s: %s\",\"n\":%ld,"
         "\"omega_over_omega0\":%.17g,\"periods\":%.17g,\"t_end\":%.17g,"
         "\"gap\":%.17g,\"fixed_step\":%.17g,\"rtol\":%.17g,\"atol\":%.17g,\"repeats\":%ld,"
         "\"seconds\":%.9g,\"rhs_evaluations\":%ld,\"rhs_evaluations_solver\":%ld,"
         "\"steps\":%ld,\"step_attempts\":%ld,\"error_test_failures\":%ld,"
         "\"nonlinear_iterations\":%ld,\"nonlinear_conv_failures\":%ld,"
         "\"linear_setups\":%ld,\"jacobian_evaluations\":%ld,\"final_state\":[",
         meth->name, version, meth->descr, n, ratio, periods, t_end, prob.g, prob.hfixed,
         rtol, abstol, repeats, best, st.nrhs, st.nrhs_solver, st.steps,
         st.attempts, st.err_fails, st.nl_iters, st.nl_fails, st.lin_setups,
         st.jac_evals);
  /* (u1..uN, v1..vN) */
  for (i = 0; i < n; i++) printf("%s%.17g", i ? "," : "", state[2 * i]);
  for (i = 0; i < n; i++) printf(",%.17g", state[2 * i + 1]);
  printf("]}\n");
  free(state);
  return 0;
}
