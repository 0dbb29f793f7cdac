/* BeltOscillator: a mass on a moving belt, held back by a spring (the
 * classical friction oscillator), as a complete FMI 2.0 Co-Simulation FMU
 * written by hand in plain C against the standard's C API, with its own
 * hand-written modelDescription.xml beside this file. It is not made by this
 * project's exporter: the tests compile it with the system C compiler, zip it
 * into BeltOscillator.fmu and import it with fricsim and with FMPy.
 *
 *   m x'' = -k x - c x' - F      F: friction force on the belt contact,
 *                                   resisting positive slip (input)
 *   v = x' - v_belt              slip velocity (output, for a friction FMU)
 *   a = x''                      acceleration (output, direct feedthrough of F)
 *
 * F is held over each communication step, which is integrated with the
 * classical Runge-Kutta method in ceil(h / h_max) equal sub-steps. Time is
 * the master's (t + h), never summed; currentCommunicationPoint must equal
 * the FMU's time to a relative 1e-9.
 *
 * Fault injection, for the importer's tests (parameters fault, fault_step,
 * fault_terminates): at the fault_step-th call of fmi2DoStep
 *   fault = 1  the state becomes NaN; the step returns fmi2OK
 *   fault = 2  fmi2Discard: the step stops half-way, at t + h/2;
 *              fmi2GetRealStatus(fmi2LastSuccessfulTime) returns that time,
 *              fmi2GetBooleanStatus(fmi2Terminated) returns fault_terminates
 *   fault = 3  fmi2Error
 *   fault = 4  fmi2Fatal: any later call on the instance, fmi2FreeInstance
 *              included, breaks FMI 2.0 §2.1.3; it is counted
 *              (belt_calls_after_fatal()) and reported on stderr.
 *   fault = 5  the step takes 0.6 s longer (it sleeps), then completes
 *              normally: an FMU that is too slow, for the host's time limit.
 * and faults that end or block the whole process, for isolated runs:
 *   fault = 6  a write through a null pointer (SIGSEGV)
 *   fault = 7  abort() (SIGABRT)
 *   fault = 8  exit(0): the process ends "successfully" mid-run
 *   fault = 9  the step hangs (sleeps 600 s)
 * belt_live_instances() counts the instances not yet freed. */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

#define GUID "{0e4e7a52-3c1d-4f7e-9b5a-4b2f1d9c8a31}"

/* Value references (modelDescription.xml). */
enum {
    VR_F, VR_X, VR_V, VR_A,                               /* input, outputs */
    VR_M, VR_K, VR_C, VR_V_BELT, VR_X0, VR_V0, VR_H_MAX,  /* Real parameters */
    N_REAL,
    VR_FAULT = N_REAL, VR_FAULT_STEP,                     /* Integer parameters */
    VR_FAULT_TERMINATES                                   /* Boolean parameter */
};

static const char *const REAL_NAMES[N_REAL] = {"F", "x", "v", "a", "m", "k", "c",
                                               "v_belt", "x0", "v0", "h_max"};
static const double REAL_START[N_REAL] = {0.0, 0.0, 0.0, 0.0, 1.0, 10.0, 0.0,
                                          0.1, 0.0, 0.1, 1e-4};

/* More sub-steps than this in one communication step are refused. */
#define MAX_SUBSTEPS 10000000.0

typedef enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    STEP_FAILED = 1 << 3,
    TERMINATED = 1 << 4,
    ERROR_STATE = 1 << 5,
    FATAL_STATE = 1 << 6
} Phase;

#define BEFORE_STEPPING (INSTANTIATED | INITIALIZATION)
#define ANY_BUT_FATAL (INSTANTIATED | INITIALIZATION | STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR_STATE)

typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocate;
    fmi2CallbackFreeMemory free;
    fmi2ComponentEnvironment env;
    char *name;
    Phase phase;
    int log_calls;

    double real[N_REAL]; /* input F and the parameters; outputs are computed */
    int fault, fault_step, fault_terminates;

    double x, xd;        /* state: position and velocity of the body */
    double time;         /* communication point reached */
    double last_successful_time;
    int steps;           /* calls of fmi2DoStep so far */
} Belt;

static int live_instances = 0;
static int calls_after_fatal = 0;

EXPORT int belt_live_instances(void) { return live_instances; }
EXPORT int belt_calls_after_fatal(void) { return calls_after_fatal; }

/* Log through the importer's logger; the message is formatted here and
 * passed as "%s", so the importer never sees a stray '%' as a format. */
static void logf_(const Belt *b, fmi2Status status, const char *category, const char *format, ...)
    __attribute__((format(printf, 4, 5)));
static void logf_(const Belt *b, fmi2Status status, const char *category, const char *format, ...) {
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
    case STEP_FAILED: return "step failed";
    case TERMINATED: return "terminated";
    case ERROR_STATE: return "error";
    case FATAL_STATE: return "fatal";
    }
    return "?";
}

/* The check every function starts with: after fmi2Fatal nothing may be
 * called; otherwise the call must be allowed in the current phase. */
static fmi2Status enter(Belt *b, const char *function, int allowed) {
    if (b == NULL) return fmi2Error; /* nothing to log to */
    if (b->phase == FATAL_STATE) {
        calls_after_fatal++;
        fprintf(stderr, "BeltOscillator: FMI VIOLATION: %s called on instance \"%s\" after fmi2Fatal\n",
                function, b->name);
        return fmi2Fatal;
    }
    if (!(b->phase & allowed)) {
        logf_(b, fmi2Error, "logStatusError", "%s: illegal call sequence: not allowed in the %s state",
              function, phase_name(b->phase));
        return fmi2Error;
    }
    if (b->log_calls) logf_(b, fmi2OK, "logCalls", "%s (t = %.17g)", function, b->time);
    return fmi2OK;
}

#define ENTER(function, allowed)                                                                   \
    do {                                                                                           \
        fmi2Status entered_ = enter((Belt *)c, function, allowed);                                 \
        if (entered_ != fmi2OK) return entered_;                                                   \
    } while (0)

static void reset_values(Belt *b) {
    memcpy(b->real, REAL_START, sizeof b->real);
    b->fault = 0;
    b->fault_step = 0;
    b->fault_terminates = 0;
    b->x = b->real[VR_X0];
    b->xd = b->real[VR_V0];
    b->time = 0.0;
    b->last_successful_time = 0.0;
    b->steps = 0;
}

static double acceleration(const Belt *b, double x, double xd) {
    const double *p = b->real;
    return (-p[VR_K] * x - p[VR_C] * xd - p[VR_F]) / p[VR_M];
}

/* The state as the outputs see it: before the first step it follows the
 * start values, which may still change during initialization. */
static void state(const Belt *b, double *x, double *xd) {
    if (b->phase & BEFORE_STEPPING) {
        *x = b->real[VR_X0];
        *xd = b->real[VR_V0];
    } else {
        *x = b->x;
        *xd = b->xd;
    }
}

/* Classical RK4 over `h` in n equal sub-steps, F held. */
static void integrate(Belt *b, double h, double n) {
    double dt = h / n;
    for (double i = 0; i < n; i++) {
        double x = b->x, v = b->xd;
        double k1x = v, k1v = acceleration(b, x, v);
        double k2x = v + 0.5 * dt * k1v, k2v = acceleration(b, x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
        double k3x = v + 0.5 * dt * k2v, k3v = acceleration(b, x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
        double k4x = v + dt * k3v, k4v = acceleration(b, x + dt * k3x, v + dt * k3v);
        b->x = x + dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        b->xd = v + dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
}

/* ---- Inquire platform and version, logging ------------------------------ */

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

static const char *const CATEGORIES[] = {"logStatusDiscard", "logStatusError", "logStatusFatal", "logCalls"};

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    Belt *b = c;
    ENTER("fmi2SetDebugLogging", ANY_BUT_FATAL);
    if (n > 0 && categories == NULL) {
        logf_(b, fmi2Error, "logStatusError", "fmi2SetDebugLogging: categories is NULL but n = %zu", n);
        return fmi2Error;
    }
    for (size_t i = 0; i < n; i++) {
        size_t k = 0;
        while (k < 4 && (categories[i] == NULL || strcmp(categories[i], CATEGORIES[k]) != 0)) k++;
        if (k == 4) {
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
    Belt probe = {.logger = functions->logger, .env = functions->componentEnvironment,
                  .name = (char *)(name ? name : "?")};
    if (name == NULL || name[0] == '\0') {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: the instance name is empty");
        return NULL;
    }
    if (type != fmi2CoSimulation) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: BeltOscillator is a co-simulation FMU only, got fmuType %d", (int)type);
        return NULL;
    }
    if (guid == NULL || strcmp(guid, GUID) != 0) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: GUID %s does not match %s", guid ? guid : "(null)", GUID);
        return NULL;
    }
    Belt *b = functions->allocateMemory(1, sizeof(Belt));
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
    b->phase = INSTANTIATED;
    b->log_calls = 0;
    (void)logging_on; /* errors are always logged; logCalls is switched by fmi2SetDebugLogging */
    reset_values(b);
    live_instances++;
    return b;
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    Belt *b = c;
    if (b == NULL) return;
    if (b->phase == FATAL_STATE) {
        enter(b, "fmi2FreeInstance", 0); /* counted and reported; the memory is left alone */
        return;
    }
    live_instances--;
    fmi2CallbackFreeMemory free_ = b->free;
    free_(b->name);
    free_(b);
}

/* ---- Initialization, termination, reset ----------------------------------- */

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                      fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    Belt *b = c;
    (void)tolerance_defined;
    (void)tolerance;
    ENTER("fmi2SetupExperiment", INSTANTIATED);
    if (!isfinite(start) || (stop_defined && !(stop >= start))) {
        logf_(b, fmi2Error, "logStatusError", "fmi2SetupExperiment: invalid start time %g or stop time %g", start, stop);
        return fmi2Error;
    }
    b->time = start;
    b->last_successful_time = start;
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Belt *b = c;
    ENTER("fmi2EnterInitializationMode", INSTANTIATED);
    b->phase = INITIALIZATION;
    return fmi2OK;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Belt *b = c;
    ENTER("fmi2ExitInitializationMode", INITIALIZATION);
    const double *p = b->real;
    const char *bad = NULL;
    double value = 0;
    if (!(p[VR_M] > 0)) bad = "m", value = p[VR_M];
    else if (!(p[VR_K] >= 0)) bad = "k", value = p[VR_K];
    else if (!(p[VR_C] >= 0)) bad = "c", value = p[VR_C];
    else if (!(p[VR_H_MAX] > 0)) bad = "h_max", value = p[VR_H_MAX];
    if (bad != NULL) {
        logf_(b, fmi2Error, "logStatusError", "fmi2ExitInitializationMode: parameter %s = %g is out of range", bad, value);
        return fmi2Error;
    }
    if (b->fault < 0 || b->fault > 9 || b->fault_step < 0) {
        logf_(b, fmi2Error, "logStatusError",
              "fmi2ExitInitializationMode: fault = %d must be 0..9 and fault_step = %d must be >= 0",
              b->fault, b->fault_step);
        return fmi2Error;
    }
    b->x = p[VR_X0];
    b->xd = p[VR_V0];
    b->phase = STEP_COMPLETE;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    Belt *b = c;
    ENTER("fmi2Terminate", STEP_COMPLETE | STEP_FAILED);
    b->phase = TERMINATED;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    Belt *b = c;
    ENTER("fmi2Reset", ANY_BUT_FATAL);
    reset_values(b);
    b->phase = INSTANTIATED;
    return fmi2OK;
}

/* ---- Getting and setting values ------------------------------------------- */

static int check_arrays(Belt *b, const char *function, const fmi2ValueReference vr[], size_t n, const void *values) {
    if (n > 0 && (vr == NULL || values == NULL)) {
        logf_(b, fmi2Error, "logStatusError", "%s: NULL array for n = %zu", function, n);
        return 0;
    }
    return 1;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Belt *b = c;
    ENTER("fmi2GetReal", ANY_BUT_FATAL);
    if (!check_arrays(b, "fmi2GetReal", vr, n, value)) return fmi2Error;
    double x, xd;
    state(b, &x, &xd);
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_X: value[i] = x; break;
        case VR_V: value[i] = xd - b->real[VR_V_BELT]; break;
        case VR_A: value[i] = acceleration(b, x, xd); break;
        default:
            if (vr[i] >= N_REAL) {
                logf_(b, fmi2Error, "logStatusError", "fmi2GetReal: no Real variable has value reference %u", vr[i]);
                return fmi2Error;
            }
            value[i] = b->real[vr[i]];
        }
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Belt *b = c;
    ENTER("fmi2SetReal", BEFORE_STEPPING | STEP_COMPLETE);
    if (!check_arrays(b, "fmi2SetReal", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) { /* check all first: a refused call changes nothing */
        if (vr[i] >= N_REAL || vr[i] == VR_X || vr[i] == VR_V || vr[i] == VR_A) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: value reference %u is not a settable Real%s%s",
                  vr[i], vr[i] < N_REAL ? " (output " : "", vr[i] < N_REAL ? REAL_NAMES[vr[i]] : "");
            return fmi2Error;
        }
        if (vr[i] != VR_F && !(b->phase & BEFORE_STEPPING)) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: parameter %s is fixed after initialization",
                  REAL_NAMES[vr[i]]);
            return fmi2Error;
        }
        if (!isfinite(value[i])) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetReal: %s = %g is not finite", REAL_NAMES[vr[i]], value[i]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) b->real[vr[i]] = value[i];
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    Belt *b = c;
    ENTER("fmi2GetInteger", ANY_BUT_FATAL);
    if (!check_arrays(b, "fmi2GetInteger", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FAULT) value[i] = b->fault;
        else if (vr[i] == VR_FAULT_STEP) value[i] = b->fault_step;
        else {
            logf_(b, fmi2Error, "logStatusError", "fmi2GetInteger: no Integer variable has value reference %u", vr[i]);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    Belt *b = c;
    ENTER("fmi2SetInteger", BEFORE_STEPPING);
    if (!check_arrays(b, "fmi2SetInteger", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_FAULT && vr[i] != VR_FAULT_STEP) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetInteger: no Integer variable has value reference %u", vr[i]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FAULT) b->fault = value[i];
        else b->fault_step = value[i];
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    Belt *b = c;
    ENTER("fmi2GetBoolean", ANY_BUT_FATAL);
    if (!check_arrays(b, "fmi2GetBoolean", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_FAULT_TERMINATES) {
            logf_(b, fmi2Error, "logStatusError", "fmi2GetBoolean: no Boolean variable has value reference %u", vr[i]);
            return fmi2Error;
        }
        value[i] = b->fault_terminates ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    Belt *b = c;
    ENTER("fmi2SetBoolean", BEFORE_STEPPING);
    if (!check_arrays(b, "fmi2SetBoolean", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_FAULT_TERMINATES) {
            logf_(b, fmi2Error, "logStatusError", "fmi2SetBoolean: no Boolean variable has value reference %u", vr[i]);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) b->fault_terminates = value[i] != fmi2False;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    Belt *b = c;
    (void)value;
    ENTER("fmi2GetString", ANY_BUT_FATAL);
    if (n == 0) return fmi2OK;
    logf_(b, fmi2Error, "logStatusError", "fmi2GetString: no String variable has value reference %u", vr ? vr[0] : 0u);
    return fmi2Error;
}

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    Belt *b = c;
    (void)value;
    ENTER("fmi2SetString", BEFORE_STEPPING | STEP_COMPLETE);
    if (n == 0) return fmi2OK;
    logf_(b, fmi2Error, "logStatusError", "fmi2SetString: no String variable has value reference %u", vr ? vr[0] : 0u);
    return fmi2Error;
}

/* ---- Optional capabilities, not provided (canGetAndSetFMUstate, ... false) -- */

static fmi2Status unsupported(fmi2Component c, const char *function, const char *capability) {
    Belt *b = c;
    ENTER(function, ANY_BUT_FATAL);
    logf_(b, fmi2Error, "logStatusError", "%s: not supported (the model description declares %s)", function,
          capability);
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s;
    return unsupported(c, "fmi2GetFMUstate", "canGetAndSetFMUstate=\"false\"");
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    (void)s;
    return unsupported(c, "fmi2SetFMUstate", "canGetAndSetFMUstate=\"false\"");
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s;
    return unsupported(c, "fmi2FreeFMUstate", "canGetAndSetFMUstate=\"false\"");
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
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                               const fmi2ValueReference z[], size_t nz, const fmi2Real dz[],
                                               fmi2Real du[]) {
    (void)u;
    (void)nu;
    (void)z;
    (void)nz;
    (void)dz;
    (void)du;
    return unsupported(c, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative=\"false\"");
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
    Belt *b = c;
    (void)no_prior;
    ENTER("fmi2DoStep", STEP_COMPLETE);
    if (!(h > 0) || !isfinite(h)) {
        logf_(b, fmi2Error, "logStatusError", "fmi2DoStep: communicationStepSize = %g must be > 0", h);
        return fmi2Error;
    }
    if (!(fabs(t - b->time) <= 1e-9 * fmax(1.0, fabs(b->time)))) {
        logf_(b, fmi2Error, "logStatusError",
              "fmi2DoStep: expected currentCommunicationPoint = %.17g but was %.17g", b->time, t);
        return fmi2Error;
    }
    double n = ceil(h / b->real[VR_H_MAX] - 1e-9);
    if (n < 1) n = 1;
    if (n > MAX_SUBSTEPS) {
        logf_(b, fmi2Error, "logStatusError", "fmi2DoStep: h = %g needs %g sub-steps of h_max = %g, more than %g",
              h, n, b->real[VR_H_MAX], MAX_SUBSTEPS);
        return fmi2Error;
    }
    b->steps++;
    int fault = b->fault_step > 0 && b->steps == b->fault_step ? b->fault : 0;
    switch (fault) {
    case 2: {
        double half = ceil(n / 2);
        integrate(b, 0.5 * h, half);
        b->time = t + 0.5 * h;
        b->last_successful_time = b->time;
        b->phase = STEP_FAILED;
        logf_(b, fmi2Discard, "logStatusDiscard",
              "fmi2DoStep: fault injected at step %d: the step from t = %.17g was completed only up to t = %.17g",
              b->steps, t, b->time);
        return fmi2Discard;
    }
    case 3:
        b->phase = ERROR_STATE;
        logf_(b, fmi2Error, "logStatusError", "fmi2DoStep: fault injected at step %d (t = %.17g): model error",
              b->steps, t);
        return fmi2Error;
    case 4:
        b->phase = FATAL_STATE;
        logf_(b, fmi2Fatal, "logStatusFatal", "fmi2DoStep: fault injected at step %d (t = %.17g): fatal", b->steps, t);
        return fmi2Fatal;
    }
    if (fault == 5) {
        struct timespec pause = {0, 600000000L};
        nanosleep(&pause, NULL);
    }
    if (fault == 6) {
        volatile double *nowhere = NULL;
        *nowhere = t;
    }
    if (fault == 7) abort();
    if (fault == 8) exit(0);
    if (fault == 9) {
        struct timespec pause = {600, 0};
        nanosleep(&pause, NULL);
    }
    integrate(b, h, n);
    if (fault == 1) b->x = b->xd = NAN;
    b->time = t + h;
    b->last_successful_time = b->time;
    return fmi2OK;
}

/* ---- Status (synchronous steps only) ---------------------------------------- */

#define STATUS_PHASES (STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR_STATE)

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Status *value) {
    (void)kind;
    (void)value;
    ENTER("fmi2GetStatus", STATUS_PHASES);
    return fmi2Discard; /* fmi2DoStepStatus and fmi2PendingStatus: the steps are synchronous */
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real *value) {
    Belt *b = c;
    ENTER("fmi2GetRealStatus", STATUS_PHASES);
    if (kind != fmi2LastSuccessfulTime || value == NULL) return fmi2Discard;
    *value = b->last_successful_time;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Integer *value) {
    (void)kind;
    (void)value;
    ENTER("fmi2GetIntegerStatus", STATUS_PHASES);
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean *value) {
    Belt *b = c;
    ENTER("fmi2GetBooleanStatus", STATUS_PHASES);
    if (kind != fmi2Terminated || value == NULL) return fmi2Discard;
    *value = b->phase == STEP_FAILED && b->fault_terminates ? fmi2True : fmi2False;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind kind, fmi2String *value) {
    (void)kind;
    (void)value;
    ENTER("fmi2GetStringStatus", STATUS_PHASES);
    return fmi2Discard;
}
