/* linear_plant.h: everything of a hand-written FMI 2.0 Co-Simulation FMU of
 * a linear plant that is not the plant's physics: the FMI types, the phases
 * (state machine), logging, the checks every call starts with, getting and
 * setting values, FMUstate, RK4 sub-stepping and the step sensitivity given
 * as directional derivatives. A plant file (two_mass_drive/two_mass_drive.c,
 * servo_axis/servo_axis.c) defines, before `#include "../common/linear_plant.h"`:
 *
 *   MODEL_IDENTIFIER  the model identifier, a string (for messages)
 *   GUID              the model description's guid, a string
 *   FASTEST_MODE      what limits h_max, a string ("the belt's mode")
 *   N_REAL            the number of Real variables, value references 0..N_REAL-1
 *   FIRST_INPUT, LAST_INPUT    the inputs' value references (contiguous)
 *   FIRST_OUTPUT, LAST_OUTPUT  the outputs' value references (contiguous)
 *   VR_H_MAX          the largest RK4 sub-step, a parameter (> 0)
 *   INTERPOLATES_INPUTS  1 if the inputs may ramp over a step (optional, 0)
 *   N_STATES          the number of continuous states
 *   STATE_VR[N_STATES]  the value reference of each state's variable (an
 *                     output, or a local of its own)
 *   FIRST_DERIVATIVE  the value reference of der(state 0); the N_STATES
 *                     derivatives follow it, locals
 *   REAL_NAMES[N_REAL], REAL_START[N_REAL]   names and start values
 *
 * and after it the plant's physics:
 *
 *   rest(p, y)            the state at rest before the first step (from the
 *                         parameters p, indexed by value reference)
 *   derivatives(p, y, dy) dy/dt at y, the inputs p[FIRST_INPUT..LAST_INPUT] held
 *   output(p, y, dy, vr)  the output vr at y (dy = derivatives(p, y))
 *   bad_parameter(p)      the value reference of the first parameter out of
 *                         range, or -1 (h_max is checked here)
 *
 * The states and their derivatives are Real variables (the model
 * description lists them under ModelStructure/Derivatives), readable in
 * every phase and never settable. Every other variable is an input or a
 * parameter, settable before initialization ends; after it only the
 * inputs are.
 *
 * The step sensitivity needs `derivatives` and `output` to be linear in the
 * state and the inputs together (no constant term; the parameters fixed):
 * then RK4 is linear too, and the derivative of the outputs after a step
 * with respect to an input held over it is the same RK4 sub-steps run from
 * a zero state with that input at 1 and the others at 0, exact up to
 * rounding. Before any step, or once an input (or its slope) is set
 * again, it is the direct feedthrough: `output` of a zero state, that
 * input at 1. With INTERPOLATES_INPUTS, an input may also ramp over the
 * next step (fmi2SetRealInputDerivatives, order 1), which ends with the
 * input at u + u'·h; the directional derivatives stay the sensitivity to
 * the input's value with its slope held (the system is linear, so the
 * ramp does not change it), as an importer expects of them.
 *
 * With a state among the knowns or a state derivative among the
 * unknowns, fmi2GetDirectionalDerivative gives the continuous-time
 * partial derivatives at the current point (∂der/∂state = A, ∂der/∂input
 * = B, ∂output/∂state = C, ∂output/∂input = D: FMI 2.0 §2.1.9, the same
 * in Co-Simulation as in Model Exchange), from which an importer can carry
 * the sensitivity of the state through its own steps; outputs by inputs
 * alone keep the step sensitivity above.
 *
 * Phases: instantiated -> initialization mode -> step complete ->
 * terminated, and error after a step that failed; each function names the
 * phases it is allowed in and refuses the others with fmi2Error and a
 * logged reason, as it refuses NULL arrays, non-finite values and value
 * references that are not of the right kind. */

#ifndef LINEAR_PLANT_H
#define LINEAR_PLANT_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* fmi2TypesPlatform.h and fmi2FunctionTypes.h, as much as is used here. */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
    const fmi2CallbackLogger logger;
    const fmi2CallbackAllocateMemory allocateMemory;
    const fmi2CallbackFreeMemory freeMemory;
    const fmi2StepFinished stepFinished;
    const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))

/* vr in first..last, in unsigned arithmetic (no always-true vr >= 0) */
#define IN_RANGE(vr, first, last) ((fmi2ValueReference)(vr) - (first) <= (fmi2ValueReference)((last) - (first)))
#define IS_INPUT(vr) IN_RANGE(vr, FIRST_INPUT, LAST_INPUT)

/* 1: canInterpolateInputs="true", fmi2SetRealInputDerivatives ramps the
 * inputs over the next step; 0: they are held, and it is refused. */
#ifndef INTERPOLATES_INPUTS
#define INTERPOLATES_INPUTS 0
#endif
#define IS_OUTPUT(vr) IN_RANGE(vr, FIRST_OUTPUT, LAST_OUTPUT)
#define IS_DERIVATIVE(vr) IN_RANGE(vr, FIRST_DERIVATIVE, FIRST_DERIVATIVE + N_STATES - 1)

/* The index of the state whose variable is `vr`, or -1. */
static int state_index(fmi2ValueReference vr) {
    for (int i = 0; i < N_STATES; i++)
        if (STATE_VR[i] == vr) return i;
    return -1;
}

/* A state or derivative that is not an output: read, never set. */
#define IS_LOCAL(vr) (IS_DERIVATIVE(vr) || (state_index(vr) >= 0 && !IS_OUTPUT(vr)))

/* What the plant file gives, after this header. */
static void rest(const double *p, double y[N_STATES]);
static void derivatives(const double *p, const double y[N_STATES], double dy[N_STATES]);
static double output(const double *p, const double y[N_STATES], const double dy[N_STATES], fmi2ValueReference vr);
static int bad_parameter(const double *p);

/* "name, name, ..." of the Real variables first..last, into `out`. */
static const char *names(fmi2ValueReference first, fmi2ValueReference last, char *out, size_t size) {
    size_t used = 0;
    out[0] = '\0';
    for (fmi2ValueReference i = first; i <= last && used < size; i++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", i > first ? ", " : "", REAL_NAMES[i]);
    return out;
}

/* More sub-steps than this in one communication step are refused. */
#define MAX_SUBSTEPS 10000000.0

/* Marks a live FMUstate (fmi2GetFMUstate); cleared when it is freed. */
#define STATE_MAGIC 0x4c505354u /* "LPST" */

typedef enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    TERMINATED = 1 << 3,
    ERROR_STATE = 1 << 4
} Phase;

#define BEFORE_STEPPING (INSTANTIATED | INITIALIZATION)
#define ANY_PHASE (INSTANTIATED | INITIALIZATION | STEP_COMPLETE | TERMINATED | ERROR_STATE)

/* Everything fmi2GetFMUstate saves and fmi2SetFMUstate restores. */
typedef struct {
    unsigned magic;      /* STATE_MAGIC in a live FMUstate, 0 in the instance */
    const void *owner;   /* the instance */
    Phase phase;
    double real[N_REAL]; /* inputs and parameters; outputs are computed */
    double y[N_STATES];  /* the plant's continuous state */
    double time;         /* communication point reached */
    double last_successful_time;
    double last_h;       /* the last step's size ... */
    double last_n;       /* ... and RK4 sub-steps */
    int stepped;         /* no input set since that step */
    double slope[N_REAL]; /* the inputs' slopes over the next step (INTERPOLATES_INPUTS) */
    int sloped;          /* some slope is not 0 */
} State;

typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocate;
    fmi2CallbackFreeMemory free;
    fmi2ComponentEnvironment env;
    char *name;
    int log_calls;
    State s;
} Instance;

/* Log through the importer's logger; the message is formatted here and
 * passed as "%s", so the importer never sees a stray '%' as a format. */
static void logf_(const Instance *b, fmi2Status status, const char *category, const char *format, ...)
    __attribute__((format(printf, 4, 5)));
static void logf_(const Instance *b, fmi2Status status, const char *category, const char *format, ...) {
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    b->logger(b->env, b->name, status, category, "%s", message);
}

static const char *phase_name(Phase p) {
    switch (p) {
    case INSTANTIATED: return "instantiated";
    case INITIALIZATION: return "initialization mode";
    case STEP_COMPLETE: return "step complete";
    case TERMINATED: return "terminated";
    case ERROR_STATE: return "error";
    }
    return "?";
}

/* The check every function starts with: the call must be allowed in the
 * current phase. */
static fmi2Status enter(Instance *b, const char *function, int allowed) {
    if (b == NULL) return fmi2Error; /* nothing to log to */
    if (!(b->s.phase & allowed)) {
        logf_(b, fmi2Error, "logStatusError", "%s: illegal call sequence: not allowed in the %s state",
              function, phase_name(b->s.phase));
        return fmi2Error;
    }
    if (b->log_calls) logf_(b, fmi2OK, "logCalls", "%s (t = %.17g)", function, b->s.time);
    return fmi2OK;
}

#define ENTER(function, allowed)                                                                   \
    do {                                                                                           \
        fmi2Status entered_ = enter((Instance *)c, function, allowed);                             \
        if (entered_ != fmi2OK) return entered_;                                                   \
    } while (0)

static void reset_values(Instance *b) {
    memset(&b->s, 0, sizeof b->s);
    b->s.owner = b;
    b->s.phase = INSTANTIATED;
    memcpy(b->s.real, REAL_START, sizeof b->s.real);
    rest(b->s.real, b->s.y);
    b->s.time = 0.0;
    b->s.last_successful_time = 0.0;
}

/* The state as the outputs see it: before the first step it follows the
 * start values, which may still change during initialization. */
static void state(const Instance *b, double y[N_STATES]) {
    if (b->s.phase & BEFORE_STEPPING) rest(b->s.real, y);
    else memcpy(y, b->s.y, sizeof b->s.y);
}

/* The values at `tau` into the step: p with each input moved along its
 * slope, into q; p itself when the inputs are held (slope NULL). */
static const double *inputs_at(const double *p, const double *slope, double tau, double q[N_REAL]) {
    if (slope == NULL) return p;
    memcpy(q, p, sizeof(double) * N_REAL);
    for (fmi2ValueReference i = FIRST_INPUT; i <= LAST_INPUT; i++) q[i] += slope[i] * tau;
    return q;
}

/* Classical RK4 of y over `h` in n equal sub-steps, the inputs held
 * (slope NULL) or each ramped from p[i] at slope[i] (fmi2SetRealInputDerivatives). */
static void integrate(const double *p, const double *slope, double y[N_STATES], double h, double n) {
    double dt = h / n, q[N_REAL];
    for (double i = 0; i < n; i++) {
        double k1[N_STATES], k2[N_STATES], k3[N_STATES], k4[N_STATES], z[N_STATES], tau = i * dt;
        derivatives(inputs_at(p, slope, tau, q), y, k1);
        for (int j = 0; j < N_STATES; j++) z[j] = y[j] + 0.5 * dt * k1[j];
        const double *mid = inputs_at(p, slope, tau + 0.5 * dt, q);
        derivatives(mid, z, k2);
        for (int j = 0; j < N_STATES; j++) z[j] = y[j] + 0.5 * dt * k2[j];
        derivatives(mid, z, k3);
        for (int j = 0; j < N_STATES; j++) z[j] = y[j] + dt * k3[j];
        derivatives(inputs_at(p, slope, tau + dt, q), z, k4);
        for (int j = 0; j < N_STATES; j++) y[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
    }
}

/* ---- Inquire platform and version, logging ------------------------------ */

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

static const char *const CATEGORIES[] = {"logStatusError", "logCalls"};
#define N_CATEGORIES (sizeof CATEGORIES / sizeof CATEGORIES[0])

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    Instance *b = c;
    ENTER("fmi2SetDebugLogging", ANY_PHASE);
    if (n > 0 && categories == NULL) {
        logf_(b, fmi2Error, "logStatusError", "fmi2SetDebugLogging: categories is NULL but n = %zu", n);
        return fmi2Error;
    }
    for (size_t i = 0; i < n; i++) {
        size_t k = 0;
        while (k < N_CATEGORIES && (categories[i] == NULL || strcmp(categories[i], CATEGORIES[k]) != 0)) k++;
        if (k == N_CATEGORIES) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetDebugLogging: unknown log category \"%s\"",
                  categories[i] ? categories[i] : "(null)");
            return fmi2Error;
        }
    }
    int calls = n == 0;
    for (size_t i = 0; i < n; i++) calls |= strcmp(categories[i], "logCalls") == 0;
    if (calls) b->log_calls = on != fmi2False;
    return fmi2OK;
}

/* ---- Creation and destruction --------------------------------------------- */

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                     const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                     fmi2Boolean logging_on) {
    (void)resources;
    (void)visible;
    if (functions == NULL || functions->logger == NULL || functions->allocateMemory == NULL ||
        functions->freeMemory == NULL)
        return NULL;
    Instance probe = {.logger = functions->logger, .env = functions->componentEnvironment,
                     .name = (char *)(name ? name : "?")};
    if (name == NULL || name[0] == '\0') {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: the instance name is empty");
        return NULL;
    }
    if (type != fmi2CoSimulation) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: %s is a co-simulation FMU only, got fmuType %d", MODEL_IDENTIFIER, (int)type);
        return NULL;
    }
    if (guid == NULL || strcmp(guid, GUID) != 0) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: GUID %s does not match %s", guid ? guid : "(null)", GUID);
        return NULL;
    }
    Instance *b = functions->allocateMemory(1, sizeof(Instance));
    char *copy = functions->allocateMemory(strlen(name) + 1, 1);
    if (b == NULL || copy == NULL) {
        functions->freeMemory(b);
        functions->freeMemory(copy);
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        return NULL;
    }
    strcpy(copy, name);
    b->logger = functions->logger;
    b->allocate = functions->allocateMemory;
    b->free = functions->freeMemory;
    b->env = functions->componentEnvironment;
    b->name = copy;
    b->log_calls = 0;
    (void)logging_on; /* errors are always logged; logCalls is switched by fmi2SetDebugLogging */
    reset_values(b);
    return b;
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    Instance *b = c;
    if (b == NULL) return;
    fmi2CallbackFreeMemory free_ = b->free;
    free_(b->name);
    free_(b);
}

/* ---- Initialization, termination, reset ----------------------------------- */

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                      fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    Instance *b = c;
    (void)tolerance_defined;
    (void)tolerance;
    ENTER("fmi2SetupExperiment", INSTANTIATED);
    if (!isfinite(start) || (stop_defined && !(stop >= start))) {
        logf_(b, fmi2Error, "logStatusError", "fmi2SetupExperiment: invalid start time %g or stop time %g", start, stop);
        return fmi2Error;
    }
    b->s.time = start;
    b->s.last_successful_time = start;
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *b = c;
    ENTER("fmi2EnterInitializationMode", INSTANTIATED);
    b->s.phase = INITIALIZATION;
    return fmi2OK;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *b = c;
    ENTER("fmi2ExitInitializationMode", INITIALIZATION);
    const double *p = b->s.real;
    int bad = bad_parameter(p);
    if (bad < 0 && !(p[VR_H_MAX] > 0)) bad = VR_H_MAX;
    if (bad >= 0) {
        logf_(b, fmi2Error, "logStatusError", "fmi2ExitInitializationMode: parameter %s = %g is out of range",
              REAL_NAMES[bad], p[bad]);
        return fmi2Error;
    }
    rest(p, b->s.y);
    b->s.phase = STEP_COMPLETE;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *b = c;
    ENTER("fmi2Terminate", STEP_COMPLETE);
    b->s.phase = TERMINATED;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    Instance *b = c;
    ENTER("fmi2Reset", ANY_PHASE);
    reset_values(b);
    return fmi2OK;
}

/* ---- Getting and setting values ------------------------------------------- */

static int check_arrays(Instance *b, const char *function, const fmi2ValueReference vr[], size_t n, const void *values) {
    if (n > 0 && (vr == NULL || values == NULL)) {
        logf_(b, fmi2Error, "logStatusError", "%s: NULL array for n = %zu", function, n);
        return 0;
    }
    return 1;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *b = c;
    ENTER("fmi2GetReal", ANY_PHASE);
    if (!check_arrays(b, "fmi2GetReal", vr, n, value)) return fmi2Error;
    double y[N_STATES], dy[N_STATES];
    state(b, y);
    derivatives(b->s.real, y, dy);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= N_REAL) {
            logf_(b, fmi2Error, "logStatusError", "fmi2GetReal: no Real variable has value reference %u", vr[i]);
            return fmi2Error;
        }
        if (IS_DERIVATIVE(vr[i])) value[i] = dy[vr[i] - FIRST_DERIVATIVE];
        else if (IS_OUTPUT(vr[i])) value[i] = output(b->s.real, y, dy, vr[i]);
        else if (state_index(vr[i]) >= 0) value[i] = y[state_index(vr[i])];
        else value[i] = b->s.real[vr[i]];
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *b = c;
    ENTER("fmi2SetReal", BEFORE_STEPPING | STEP_COMPLETE);
    if (!check_arrays(b, "fmi2SetReal", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) { /* check all first: a refused call changes nothing */
        if (vr[i] >= N_REAL || IS_OUTPUT(vr[i]) || IS_LOCAL(vr[i])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: value reference %u is not a settable Real%s%s%s",
                  vr[i],
                  vr[i] >= N_REAL ? "" : IS_OUTPUT(vr[i]) ? " (output " : " (state or state derivative ",
                  vr[i] < N_REAL ? REAL_NAMES[vr[i]] : "", vr[i] < N_REAL ? ")" : "");
            return fmi2Error;
        }
        if (!IS_INPUT(vr[i]) && !(b->s.phase & BEFORE_STEPPING)) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: parameter %s is fixed after initialization",
                  REAL_NAMES[vr[i]]);
            return fmi2Error;
        }
        if (!isfinite(value[i])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: %s = %g is not finite", REAL_NAMES[vr[i]], value[i]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) {
        b->s.real[vr[i]] = value[i];
        if (IS_INPUT(vr[i])) b->s.stepped = 0;
    }
    return fmi2OK;
}

/* Integer, Boolean and String: the model has no such variable, so only
 * n = 0 succeeds. */
static fmi2Status no_variables(fmi2Component c, const char *function, const char *type, int allowed,
                               const fmi2ValueReference vr[], size_t n, const void *values) {
    Instance *b = c;
    ENTER(function, allowed);
    if (!check_arrays(b, function, vr, n, values)) return fmi2Error;
    if (n == 0) return fmi2OK;
    logf_(b, fmi2Error, "logStatusError", "%s: no %s variable has value reference %u", function, type, vr[0]);
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    return no_variables(c, "fmi2GetInteger", "Integer", ANY_PHASE, vr, n, value);
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    return no_variables(c, "fmi2SetInteger", "Integer", BEFORE_STEPPING | STEP_COMPLETE, vr, n, value);
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    return no_variables(c, "fmi2GetBoolean", "Boolean", ANY_PHASE, vr, n, value);
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    return no_variables(c, "fmi2SetBoolean", "Boolean", BEFORE_STEPPING | STEP_COMPLETE, vr, n, value);
}

EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    return no_variables(c, "fmi2GetString", "String", ANY_PHASE, vr, n, value);
}

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    return no_variables(c, "fmi2SetString", "String", BEFORE_STEPPING | STEP_COMPLETE, vr, n, value);
}

/* ---- FMU state (canGetAndSetFMUstate="true") -------------------------------- */

/* A live FMUstate of this instance, or NULL after logging why not. */
static State *own_state(Instance *b, const char *function, fmi2FMUstate s) {
    State *saved = s;
    if (saved == NULL) {
        logf_(b, fmi2Error, "logStatusError", "%s: the FMUstate is NULL", function);
        return NULL;
    }
    if (saved->magic != STATE_MAGIC || saved->owner != b) {
        logf_(b, fmi2Error, "logStatusError",
              "%s: not an FMUstate of this instance (freed, or from another instance)", function);
        return NULL;
    }
    return saved;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    Instance *b = c;
    ENTER("fmi2GetFMUstate", ANY_PHASE);
    if (s == NULL) {
        logf_(b, fmi2Error, "logStatusError", "fmi2GetFMUstate: the FMUstate pointer is NULL");
        return fmi2Error;
    }
    State *saved;
    if (*s == NULL) { /* a new one */
        saved = b->allocate(1, sizeof(State));
        if (saved == NULL) {
            logf_(b, fmi2Error, "logStatusError", "fmi2GetFMUstate: out of memory");
            return fmi2Error;
        }
    } else { /* one returned before and not freed since: overwritten */
        saved = own_state(b, "fmi2GetFMUstate", *s);
        if (saved == NULL) return fmi2Error;
    }
    *saved = b->s;
    saved->magic = STATE_MAGIC;
    saved->owner = b;
    *s = saved;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    Instance *b = c;
    ENTER("fmi2SetFMUstate", ANY_PHASE);
    State *saved = own_state(b, "fmi2SetFMUstate", s);
    if (saved == NULL) return fmi2Error;
    b->s = *saved;
    b->s.magic = 0;
    return fmi2OK;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    Instance *b = c;
    ENTER("fmi2FreeFMUstate", ANY_PHASE);
    if (s == NULL || *s == NULL) return fmi2OK; /* FMI 2.0 §2.1.8: a null pointer is ignored */
    State *saved = own_state(b, "fmi2FreeFMUstate", *s);
    if (saved == NULL) return fmi2Error;
    saved->magic = 0;
    b->free(saved);
    *s = NULL;
    return fmi2OK;
}

/* ---- Optional capabilities, not provided (canSerializeFMUstate, ... false) -- */

static fmi2Status unsupported(fmi2Component c, const char *function, const char *capability) {
    Instance *b = c;
    ENTER(function, ANY_PHASE);
    logf_(b, fmi2Error, "logStatusError", "%s: not supported (the model description declares %s)", function,
          capability);
    return fmi2Error;
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    (void)s;
    (void)size;
    return unsupported(c, "fmi2SerializedFMUstateSize", "canSerializeFMUstate=\"false\"");
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte bytes[], size_t size) {
    (void)s;
    (void)bytes;
    (void)size;
    return unsupported(c, "fmi2SerializeFMUstate", "canSerializeFMUstate=\"false\"");
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *s) {
    (void)bytes;
    (void)size;
    (void)s;
    return unsupported(c, "fmi2DeSerializeFMUstate", "canSerializeFMUstate=\"false\"");
}
/* d(outputs)/d(input `known`): the last step's sensitivity when `stepped`,
 * else the direct feedthrough. `d` is indexed by value reference. */
static void output_sensitivity(const Instance *b, fmi2ValueReference known, double d[N_REAL]) {
    memset(d, 0, sizeof(double) * N_REAL);
    double unit[N_REAL], y[N_STATES] = {0}, dy[N_STATES];
    memcpy(unit, b->s.real, sizeof unit);
    for (fmi2ValueReference i = FIRST_INPUT; i <= LAST_INPUT; i++) unit[i] = known == i;
    if (b->s.stepped) integrate(unit, NULL, y, b->s.last_h, b->s.last_n);
    derivatives(unit, y, dy); /* outputs that are derivatives, along the sensitivity */
    for (fmi2ValueReference o = FIRST_OUTPUT; o <= LAST_OUTPUT; o++) d[o] = output(unit, y, dy, o);
}

/* The continuous-time partial derivatives of the outputs and the state
 * derivatives by one known at the current point, indexed by value
 * reference: the model is linear in the state and the inputs together, so
 * they are the outputs and derivatives at a unit state or input with
 * everything else 0. */
static void continuous_partials(const Instance *b, fmi2ValueReference known, double d[N_REAL]) {
    memset(d, 0, sizeof(double) * N_REAL);
    double unit[N_REAL], y[N_STATES] = {0}, dy[N_STATES];
    memcpy(unit, b->s.real, sizeof unit);
    for (fmi2ValueReference i = FIRST_INPUT; i <= LAST_INPUT; i++) unit[i] = known == i;
    int k = state_index(known);
    if (k >= 0) y[k] = 1.0;
    derivatives(unit, y, dy);
    for (fmi2ValueReference o = FIRST_OUTPUT; o <= LAST_OUTPUT; o++) d[o] = output(unit, y, dy, o);
    for (int i = 0; i < N_STATES; i++) d[FIRST_DERIVATIVE + i] = dy[i];
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference unknown[],
                                               size_t n_unknown, const fmi2ValueReference known[],
                                               size_t n_known, const fmi2Real d_known[],
                                               fmi2Real d_unknown[]) {
    Instance *b = c;
    ENTER("fmi2GetDirectionalDerivative", INITIALIZATION | STEP_COMPLETE);
    if ((n_unknown > 0 && (unknown == NULL || d_unknown == NULL)) ||
        (n_known > 0 && (known == NULL || d_known == NULL))) {
        logf_(b, fmi2Error, "logStatusError",
              "fmi2GetDirectionalDerivative: NULL array for %zu unknowns and %zu knowns", n_unknown, n_known);
        return fmi2Error;
    }
    char list[256];
    /* a state among the knowns or a derivative among the unknowns: the
     * continuous-time partials; else the step sensitivity */
    int continuous = 0;
    for (size_t i = 0; i < n_unknown; i++) {
        if (!IS_OUTPUT(unknown[i]) && !IS_DERIVATIVE(unknown[i])) {
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2GetDirectionalDerivative: unknown value reference %u is not an output (%s) or a state derivative",
                  unknown[i], names(FIRST_OUTPUT, LAST_OUTPUT, list, sizeof list));
            return fmi2Error;
        }
        continuous |= IS_DERIVATIVE(unknown[i]);
    }
    for (size_t j = 0; j < n_known; j++) {
        if (!IS_INPUT(known[j]) && state_index(known[j]) < 0) {
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2GetDirectionalDerivative: known value reference %u is not an input (%s) or a state", known[j],
                  names(FIRST_INPUT, LAST_INPUT, list, sizeof list));
            return fmi2Error;
        }
        if (!isfinite(d_known[j])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2GetDirectionalDerivative: seed %g of %s is not finite",
                  d_known[j], REAL_NAMES[known[j]]);
            return fmi2Error;
        }
        continuous |= state_index(known[j]) >= 0;
    }
    for (size_t i = 0; i < n_unknown; i++) d_unknown[i] = 0.0;
    for (size_t j = 0; j < n_known; j++) {
        double d[N_REAL];
        if (continuous) continuous_partials(b, known[j], d);
        else output_sensitivity(b, known[j], d);
        for (size_t i = 0; i < n_unknown; i++) d_unknown[i] += d[unknown[i]] * d_known[j];
    }
    return fmi2OK;
}
#if INTERPOLATES_INPUTS
/* canInterpolateInputs: first derivatives only; each input ramps along
 * its slope over the next step, at whose end it holds u + u'·h. */
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2Integer order[], const fmi2Real value[]) {
    Instance *b = c;
    ENTER("fmi2SetRealInputDerivatives", BEFORE_STEPPING | STEP_COMPLETE);
    if (!check_arrays(b, "fmi2SetRealInputDerivatives", vr, n, value) ||
        !check_arrays(b, "fmi2SetRealInputDerivatives", vr, n, order))
        return fmi2Error;
    char list[256];
    for (size_t i = 0; i < n; i++) { /* check all first: a refused call changes nothing */
        if (!IS_INPUT(vr[i])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetRealInputDerivatives: value reference %u is not an input (%s)",
                  vr[i], names(FIRST_INPUT, LAST_INPUT, list, sizeof list));
            return fmi2Error;
        }
        if (order[i] != 1) {
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2SetRealInputDerivatives: derivative order %d of %s is not supported (only 1: inputs ramp linearly)",
                  order[i], REAL_NAMES[vr[i]]);
            return fmi2Error;
        }
        if (!isfinite(value[i])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetRealInputDerivatives: derivative %g of %s is not finite",
                  value[i], REAL_NAMES[vr[i]]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) {
        b->s.slope[vr[i]] = value[i];
        b->s.sloped |= value[i] != 0.0;
        b->s.stepped = 0;
    }
    return fmi2OK;
}
#else
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)n;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives", "canInterpolateInputs=\"false\"");
}
#endif
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)n;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives", "maxOutputDerivativeOrder=\"0\"");
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) {
    return unsupported(c, "fmi2CancelStep", "canRunAsynchronuously=\"false\"");
}

/* ---- Stepping --------------------------------------------------------------- */

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    Instance *b = c;
    (void)no_prior;
    ENTER("fmi2DoStep", STEP_COMPLETE);
    if (!(h > 0) || !isfinite(h)) {
        logf_(b, fmi2Error, "logStatusError", "fmi2DoStep: communicationStepSize = %g must be > 0", h);
        return fmi2Error;
    }
    if (!(fabs(t - b->s.time) <= 1e-9 * fmax(1.0, fabs(b->s.time)))) {
        logf_(b, fmi2Error, "logStatusError",
              "fmi2DoStep: expected currentCommunicationPoint = %.17g but was %.17g", b->s.time, t);
        return fmi2Error;
    }
    double n = ceil(h / b->s.real[VR_H_MAX] - 1e-9);
    if (n < 1) n = 1;
    if (n > MAX_SUBSTEPS) {
        logf_(b, fmi2Error, "logStatusError", "fmi2DoStep: h = %g needs %g sub-steps of h_max = %g, more than %g",
              h, n, b->s.real[VR_H_MAX], MAX_SUBSTEPS);
        return fmi2Error;
    }
    double y[N_STATES];
    memcpy(y, b->s.y, sizeof y);
    integrate(b->s.real, b->s.sloped ? b->s.slope : NULL, y, h, n);
    for (int j = 0; j < N_STATES; j++) {
        if (!isfinite(y[j])) {
            b->s.phase = ERROR_STATE;
            char inputs[256];
            size_t used = 0;
            for (fmi2ValueReference i = FIRST_INPUT; i <= LAST_INPUT && used < sizeof inputs; i++)
                used += (size_t)snprintf(inputs + used, sizeof inputs - used, "%s%s = %g",
                                         i > FIRST_INPUT ? ", " : "", REAL_NAMES[i], b->s.real[i]);
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2DoStep: the state is not finite after the step from t = %.17g (%s); "
                  "h_max = %g may be too large for %s: the state is left as it was",
                  t, inputs, b->s.real[VR_H_MAX], FASTEST_MODE);
            return fmi2Error;
        }
    }
    memcpy(b->s.y, y, sizeof y);
    b->s.time = t + h;
    b->s.last_successful_time = b->s.time;
    b->s.last_h = h;
    b->s.last_n = n;
    b->s.stepped = 1;
    if (b->s.sloped) { /* the inputs as the step ended (u + u'·h); a slope holds for one step */
        for (fmi2ValueReference i = FIRST_INPUT; i <= LAST_INPUT; i++) {
            b->s.real[i] += b->s.slope[i] * h;
            b->s.slope[i] = 0.0;
        }
        b->s.sloped = 0;
    }
    return fmi2OK;
}

/* ---- Status (synchronous steps only) ---------------------------------------- */

#define STATUS_PHASES (STEP_COMPLETE | TERMINATED | ERROR_STATE)

static int check_status_value(Instance *b, const char *function, const void *value) {
    if (value == NULL) {
        logf_(b, fmi2Error, "logStatusError", "%s: value is NULL", function);
        return 0;
    }
    return 1;
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Status *value) {
    Instance *b = c;
    (void)kind;
    ENTER("fmi2GetStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetStatus", value)) return fmi2Error;
    return fmi2Discard; /* fmi2DoStepStatus and fmi2PendingStatus: the steps are synchronous */
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real *value) {
    Instance *b = c;
    ENTER("fmi2GetRealStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetRealStatus", value)) return fmi2Error;
    if (kind != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = b->s.last_successful_time;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Integer *value) {
    Instance *b = c;
    (void)kind;
    ENTER("fmi2GetIntegerStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetIntegerStatus", value)) return fmi2Error;
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean *value) {
    Instance *b = c;
    ENTER("fmi2GetBooleanStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetBooleanStatus", value)) return fmi2Error;
    if (kind != fmi2Terminated) return fmi2Discard;
    *value = fmi2False; /* no step is ever discarded */
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind kind, fmi2String *value) {
    Instance *b = c;
    (void)kind;
    ENTER("fmi2GetStringStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetStringStatus", value)) return fmi2Error;
    return fmi2Discard;
}

#endif /* LINEAR_PLANT_H */
