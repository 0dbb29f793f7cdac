/* TwoMassDrive: a motor driving a load through a belt (or gear) spring, with
 * friction on the load, as a complete FMI 2.0 Co-Simulation FMU written by
 * hand in plain C against the standard's C API, with its own hand-written
 * modelDescription.xml beside this file. It is not made by this project's
 * exporter: the tests compile it with the system C compiler, zip it into
 * TwoMassDrive.fmu and import it with fricsim and with FMPy.
 *
 *   m_m x_m'' = u - k_b (x_m - x_l) - c_b (x_m' - x_l') - c_m x_m'
 *   m_l x_l'' = k_b (x_m - x_l) + c_b (x_m' - x_l') - F
 *
 *   u   motor force (input, e.g. from measurements)
 *   F   friction force on the load, resisting positive load velocity (input)
 *   x_m, x_l   motor and load positions (outputs)
 *   v = x_l'   load velocity: the slip velocity of a friction FMU (output)
 *   a = x_l''  load acceleration (output, direct feedthrough of F only: u
 *              reaches the load through the spring, i.e. through the state)
 *
 * Both masses start at rest at x0 with the spring relaxed; before the first
 * step the outputs follow the start values, which may still change during
 * initialization. The inputs are held over each communication step (FMI 2.0,
 * no input derivatives), which is integrated with the classical Runge-Kutta
 * method in ceil(h / h_max) equal sub-steps. Time is the master's (t + h),
 * never summed; currentCommunicationPoint must equal the FMU's time to a
 * relative 1e-9. A step whose result is not finite leaves the state as it
 * was and returns fmi2Error (RK4 is unstable once h_max exceeds about
 * 2.8 / sqrt(k_b (1/m_m + 1/m_l)), the belt mode's period / 2.2).
 *
 * canGetAndSetFMUstate: an FMUstate is a copy of the instance's State struct
 * (phase, values, state, time), allocated with the importer's allocator; it
 * belongs to the instance that took it. canSerializeFMUstate is false.
 *
 * providesDirectionalDerivative: right after fmi2DoStep, before an input is
 * set again, the derivative of the outputs with respect to u and F is the
 * step's sensitivity to the input held over that step (what a strongly
 * coupled master's Newton iteration needs); otherwise it is the direct
 * feedthrough, da/dF = -1/m_l and nothing else. The plant is linear, so the
 * sensitivity is exact: RK4 is affine in the state and the inputs, and its
 * derivative along an input is the same RK4 sub-steps run from a zero state
 * with that input at 1 and the other at 0. */

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

#define GUID "{b323c20a-8726-4f8e-84df-75a94689c418}"

/* Value references (modelDescription.xml). */
enum {
    VR_U, VR_F,                                  /* inputs */
    VR_X_M, VR_X_L, VR_V, VR_A,                  /* outputs */
    VR_M_M, VR_M_L, VR_K_B, VR_C_B, VR_C_M,      /* Real parameters */
    VR_X0, VR_H_MAX,
    N_REAL
};

static const char *const REAL_NAMES[N_REAL] = {"u",   "F",   "x_m", "x_l", "v",  "a",    "m_m",
                                               "m_l", "k_b", "c_b", "c_m", "x0", "h_max"};
static const double REAL_START[N_REAL] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5,
                                          2.0, 2e4, 20.0, 1.0, 0.0, 1e-4};

#define IS_OUTPUT(vr) ((vr) >= VR_X_M && (vr) <= VR_A)

/* The continuous state. */
enum { XM, VM, XL, VL, N_STATES };

/* More sub-steps than this in one communication step are refused. */
#define MAX_SUBSTEPS 10000000.0

/* Marks a live FMUstate (fmi2GetFMUstate); cleared when it is freed. */
#define STATE_MAGIC 0x544d4453u /* "TMDS" */

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
    double y[N_STATES];  /* x_m, x_m', x_l, x_l' */
    double time;         /* communication point reached */
    double last_successful_time;
    double last_h;       /* the last step's size ... */
    double last_n;       /* ... and RK4 sub-steps */
    int stepped;         /* no input set since that step */
} State;

typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocate;
    fmi2CallbackFreeMemory free;
    fmi2ComponentEnvironment env;
    char *name;
    int log_calls;
    State s;
} TwoMass;

/* Log through the importer's logger; the message is formatted here and
 * passed as "%s", so the importer never sees a stray '%' as a format. */
static void logf_(const TwoMass *b, fmi2Status status, const char *category, const char *format, ...)
    __attribute__((format(printf, 4, 5)));
static void logf_(const TwoMass *b, fmi2Status status, const char *category, const char *format, ...) {
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
static fmi2Status enter(TwoMass *b, const char *function, int allowed) {
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
        fmi2Status entered_ = enter((TwoMass *)c, function, allowed);                              \
        if (entered_ != fmi2OK) return entered_;                                                   \
    } while (0)

static void rest(const double *p, double y[N_STATES]) {
    y[XM] = p[VR_X0];
    y[VM] = 0.0;
    y[XL] = p[VR_X0];
    y[VL] = 0.0;
}

static void reset_values(TwoMass *b) {
    memset(&b->s, 0, sizeof b->s);
    b->s.owner = b;
    b->s.phase = INSTANTIATED;
    memcpy(b->s.real, REAL_START, sizeof b->s.real);
    rest(b->s.real, b->s.y);
    b->s.time = 0.0;
    b->s.last_successful_time = 0.0;
}

/* dy/dt at y, the inputs u and F held. */
static void derivatives(const double *p, const double y[N_STATES], double dy[N_STATES]) {
    double belt = p[VR_K_B] * (y[XM] - y[XL]) + p[VR_C_B] * (y[VM] - y[VL]);
    dy[XM] = y[VM];
    dy[VM] = (p[VR_U] - belt - p[VR_C_M] * y[VM]) / p[VR_M_M];
    dy[XL] = y[VL];
    dy[VL] = (belt - p[VR_F]) / p[VR_M_L];
}

/* The state as the outputs see it: before the first step it follows the
 * start values, which may still change during initialization. */
static void state(const TwoMass *b, double y[N_STATES]) {
    if (b->s.phase & BEFORE_STEPPING) rest(b->s.real, y);
    else memcpy(y, b->s.y, sizeof b->s.y);
}

/* Classical RK4 of y over `h` in n equal sub-steps, the inputs held. */
static void integrate(const double *p, double y[N_STATES], double h, double n) {
    double dt = h / n;
    for (double i = 0; i < n; i++) {
        double k1[N_STATES], k2[N_STATES], k3[N_STATES], k4[N_STATES], z[N_STATES];
        derivatives(p, y, k1);
        for (int j = 0; j < N_STATES; j++) z[j] = y[j] + 0.5 * dt * k1[j];
        derivatives(p, z, k2);
        for (int j = 0; j < N_STATES; j++) z[j] = y[j] + 0.5 * dt * k2[j];
        derivatives(p, z, k3);
        for (int j = 0; j < N_STATES; j++) z[j] = y[j] + dt * k3[j];
        derivatives(p, z, k4);
        for (int j = 0; j < N_STATES; j++) y[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
    }
}

/* ---- Inquire platform and version, logging ------------------------------ */

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

static const char *const CATEGORIES[] = {"logStatusError", "logCalls"};
#define N_CATEGORIES (sizeof CATEGORIES / sizeof CATEGORIES[0])

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    TwoMass *b = c;
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
    TwoMass probe = {.logger = functions->logger, .env = functions->componentEnvironment,
                     .name = (char *)(name ? name : "?")};
    if (name == NULL || name[0] == '\0') {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: the instance name is empty");
        return NULL;
    }
    if (type != fmi2CoSimulation) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: TwoMassDrive is a co-simulation FMU only, got fmuType %d", (int)type);
        return NULL;
    }
    if (guid == NULL || strcmp(guid, GUID) != 0) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: GUID %s does not match %s", guid ? guid : "(null)", GUID);
        return NULL;
    }
    TwoMass *b = functions->allocateMemory(1, sizeof(TwoMass));
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
    TwoMass *b = c;
    if (b == NULL) return;
    fmi2CallbackFreeMemory free_ = b->free;
    free_(b->name);
    free_(b);
}

/* ---- Initialization, termination, reset ----------------------------------- */

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                      fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    TwoMass *b = c;
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
    TwoMass *b = c;
    ENTER("fmi2EnterInitializationMode", INSTANTIATED);
    b->s.phase = INITIALIZATION;
    return fmi2OK;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    TwoMass *b = c;
    ENTER("fmi2ExitInitializationMode", INITIALIZATION);
    const double *p = b->s.real;
    const char *bad = NULL;
    double value = 0;
    if (!(p[VR_M_M] > 0)) bad = "m_m", value = p[VR_M_M];
    else if (!(p[VR_M_L] > 0)) bad = "m_l", value = p[VR_M_L];
    else if (!(p[VR_K_B] >= 0)) bad = "k_b", value = p[VR_K_B];
    else if (!(p[VR_C_B] >= 0)) bad = "c_b", value = p[VR_C_B];
    else if (!(p[VR_C_M] >= 0)) bad = "c_m", value = p[VR_C_M];
    else if (!(p[VR_H_MAX] > 0)) bad = "h_max", value = p[VR_H_MAX];
    if (bad != NULL) {
        logf_(b, fmi2Error, "logStatusError", "fmi2ExitInitializationMode: parameter %s = %g is out of range", bad, value);
        return fmi2Error;
    }
    rest(p, b->s.y);
    b->s.phase = STEP_COMPLETE;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    TwoMass *b = c;
    ENTER("fmi2Terminate", STEP_COMPLETE);
    b->s.phase = TERMINATED;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    TwoMass *b = c;
    ENTER("fmi2Reset", ANY_PHASE);
    reset_values(b);
    return fmi2OK;
}

/* ---- Getting and setting values ------------------------------------------- */

static int check_arrays(TwoMass *b, const char *function, const fmi2ValueReference vr[], size_t n, const void *values) {
    if (n > 0 && (vr == NULL || values == NULL)) {
        logf_(b, fmi2Error, "logStatusError", "%s: NULL array for n = %zu", function, n);
        return 0;
    }
    return 1;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    TwoMass *b = c;
    ENTER("fmi2GetReal", ANY_PHASE);
    if (!check_arrays(b, "fmi2GetReal", vr, n, value)) return fmi2Error;
    double y[N_STATES], dy[N_STATES];
    state(b, y);
    derivatives(b->s.real, y, dy);
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_X_M: value[i] = y[XM]; break;
        case VR_X_L: value[i] = y[XL]; break;
        case VR_V: value[i] = y[VL]; break;
        case VR_A: value[i] = dy[VL]; break;
        default:
            if (vr[i] >= N_REAL) {
                logf_(b, fmi2Error, "logStatusError", "fmi2GetReal: no Real variable has value reference %u", vr[i]);
                return fmi2Error;
            }
            value[i] = b->s.real[vr[i]];
        }
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    TwoMass *b = c;
    ENTER("fmi2SetReal", BEFORE_STEPPING | STEP_COMPLETE);
    if (!check_arrays(b, "fmi2SetReal", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) { /* check all first: a refused call changes nothing */
        if (vr[i] >= N_REAL || IS_OUTPUT(vr[i])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: value reference %u is not a settable Real%s%s",
                  vr[i], vr[i] < N_REAL ? " (output " : "", vr[i] < N_REAL ? REAL_NAMES[vr[i]] : "");
            return fmi2Error;
        }
        if (vr[i] != VR_U && vr[i] != VR_F && !(b->s.phase & BEFORE_STEPPING)) {
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
        if (vr[i] == VR_U || vr[i] == VR_F) b->s.stepped = 0;
    }
    return fmi2OK;
}

/* Integer, Boolean and String: the model has no such variable, so only
 * n = 0 succeeds. */
static fmi2Status no_variables(fmi2Component c, const char *function, const char *type, int allowed,
                               const fmi2ValueReference vr[], size_t n, const void *values) {
    TwoMass *b = c;
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
static State *own_state(TwoMass *b, const char *function, fmi2FMUstate s) {
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
    TwoMass *b = c;
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
    TwoMass *b = c;
    ENTER("fmi2SetFMUstate", ANY_PHASE);
    State *saved = own_state(b, "fmi2SetFMUstate", s);
    if (saved == NULL) return fmi2Error;
    b->s = *saved;
    b->s.magic = 0;
    return fmi2OK;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    TwoMass *b = c;
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
    TwoMass *b = c;
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
static void output_sensitivity(const TwoMass *b, fmi2ValueReference known, double d[N_REAL]) {
    memset(d, 0, sizeof(double) * N_REAL);
    const double *p = b->s.real;
    if (!b->s.stepped) {
        if (known == VR_F) d[VR_A] = -1.0 / p[VR_M_L];
        return;
    }
    double unit[N_REAL], y[N_STATES] = {0}, dy[N_STATES];
    memcpy(unit, p, sizeof unit);
    unit[VR_U] = known == VR_U;
    unit[VR_F] = known == VR_F;
    integrate(unit, y, b->s.last_h, b->s.last_n);
    derivatives(unit, y, dy); /* a = x_l'' along the sensitivity */
    d[VR_X_M] = y[XM];
    d[VR_X_L] = y[XL];
    d[VR_V] = y[VL];
    d[VR_A] = dy[VL];
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference unknown[],
                                               size_t n_unknown, const fmi2ValueReference known[],
                                               size_t n_known, const fmi2Real d_known[],
                                               fmi2Real d_unknown[]) {
    TwoMass *b = c;
    ENTER("fmi2GetDirectionalDerivative", INITIALIZATION | STEP_COMPLETE);
    if ((n_unknown > 0 && (unknown == NULL || d_unknown == NULL)) ||
        (n_known > 0 && (known == NULL || d_known == NULL))) {
        logf_(b, fmi2Error, "logStatusError",
              "fmi2GetDirectionalDerivative: NULL array for %zu unknowns and %zu knowns", n_unknown, n_known);
        return fmi2Error;
    }
    for (size_t i = 0; i < n_unknown; i++)
        if (!IS_OUTPUT(unknown[i])) {
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2GetDirectionalDerivative: unknown value reference %u is not an output (x_m, x_l, v, a)",
                  unknown[i]);
            return fmi2Error;
        }
    for (size_t j = 0; j < n_known; j++) {
        if (known[j] != VR_U && known[j] != VR_F) {
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2GetDirectionalDerivative: known value reference %u is not an input (u, F)", known[j]);
            return fmi2Error;
        }
        if (!isfinite(d_known[j])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2GetDirectionalDerivative: seed %g of %s is not finite",
                  d_known[j], REAL_NAMES[known[j]]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n_unknown; i++) d_unknown[i] = 0.0;
    for (size_t j = 0; j < n_known; j++) {
        double d[N_REAL];
        output_sensitivity(b, known[j], d);
        for (size_t i = 0; i < n_unknown; i++) d_unknown[i] += d[unknown[i]] * d_known[j];
    }
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)n;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives", "canInterpolateInputs=\"false\"");
}
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
    TwoMass *b = c;
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
    integrate(b->s.real, y, h, n);
    for (int j = 0; j < N_STATES; j++) {
        if (!isfinite(y[j])) {
            b->s.phase = ERROR_STATE;
            logf_(b, fmi2Error, "logStatusError",
                  "fmi2DoStep: the state is not finite after the step from t = %.17g (u = %g, F = %g); "
                  "h_max = %g may be too large for the belt's mode: the state is left as it was",
                  t, b->s.real[VR_U], b->s.real[VR_F], b->s.real[VR_H_MAX]);
            return fmi2Error;
        }
    }
    memcpy(b->s.y, y, sizeof y);
    b->s.time = t + h;
    b->s.last_successful_time = b->s.time;
    b->s.last_h = h;
    b->s.last_n = n;
    b->s.stepped = 1;
    return fmi2OK;
}

/* ---- Status (synchronous steps only) ---------------------------------------- */

#define STATUS_PHASES (STEP_COMPLETE | TERMINATED | ERROR_STATE)

static int check_status_value(TwoMass *b, const char *function, const void *value) {
    if (value == NULL) {
        logf_(b, fmi2Error, "logStatusError", "%s: value is NULL", function);
        return 0;
    }
    return 1;
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Status *value) {
    TwoMass *b = c;
    (void)kind;
    ENTER("fmi2GetStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetStatus", value)) return fmi2Error;
    return fmi2Discard; /* fmi2DoStepStatus and fmi2PendingStatus: the steps are synchronous */
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real *value) {
    TwoMass *b = c;
    ENTER("fmi2GetRealStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetRealStatus", value)) return fmi2Error;
    if (kind != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = b->s.last_successful_time;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Integer *value) {
    TwoMass *b = c;
    (void)kind;
    ENTER("fmi2GetIntegerStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetIntegerStatus", value)) return fmi2Error;
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean *value) {
    TwoMass *b = c;
    ENTER("fmi2GetBooleanStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetBooleanStatus", value)) return fmi2Error;
    if (kind != fmi2Terminated) return fmi2Discard;
    *value = fmi2False; /* no step is ever discarded */
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind kind, fmi2String *value) {
    TwoMass *b = c;
    (void)kind;
    ENTER("fmi2GetStringStatus", STATUS_PHASES);
    if (!check_status_value(b, "fmi2GetStringStatus", value)) return fmi2Error;
    return fmi2Discard;
}
