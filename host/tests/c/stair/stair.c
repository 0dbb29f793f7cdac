/* Stair: a counter that climbs one stair every second and ends the
 * simulation at the top, as a complete FMI 2.0 Co-Simulation FMU written by
 * hand in plain C, with its own modelDescription.xml beside this file. It
 * behaves like the Modelica Reference FMU Stair: the tests compile it with
 * the system C compiler, zip it into Stair.fmu and import it with fricsim
 * and with FMPy.
 *
 *   counter   Integer output, start 1 (initial="exact": settable), one more
 *             at every whole second t = 1, 2, ... (counted from t = 0)
 *   even      Boolean output: counter is even
 *   height    Real output: counter * step_height
 *
 * When counter reaches `top` (10: at t = 9), fmi2DoStep stops there and
 * returns fmi2Discard: fmi2GetRealStatus(fmi2LastSuccessfulTime) gives the
 * time of that second and fmi2GetBooleanStatus(fmi2Terminated) gives
 * `terminates` (true: the FMU ends the simulation, FMI 2.0.4 §4.2.3; false:
 * only a discarded step). A later fmi2DoStep is an error.
 *
 * For the tests of how an importer ends a run, two environment variables:
 *   STAIR_TRACE=FILE            fmi2SetupExperiment (with the stop time
 *                               it was told, if any), fmi2Terminate and
 *                               fmi2FreeInstance append a line each to
 *                               FILE (the call, the phase, the time)
 *   STAIR_TERMINATE_FAILS=TEXT  fmi2Terminate logs TEXT and returns
 *                               fmi2Error */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
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

#define GUID "{5d1f2c3e-8a47-4b6e-9c0d-7e3f1a2b4c5d}"

/* Value references, one numbering per type (modelDescription.xml). */
enum { VR_HEIGHT, VR_STEP_HEIGHT, VR_END_TIME };  /* Real */
enum { VR_COUNTER, VR_TOP };                      /* Integer */
enum { VR_EVEN, VR_TERMINATES };                  /* Boolean */
enum { VR_LABEL };                                /* String */

#define LABEL_SIZE 256

typedef enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    STEP_FAILED = 1 << 3,
    TERMINATED = 1 << 4,
    ERROR_STATE = 1 << 5
} Phase;

#define BEFORE_STEPPING (INSTANTIATED | INITIALIZATION)
#define ANY (INSTANTIATED | INITIALIZATION | STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR_STATE)
#define STATUS_PHASES (STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR_STATE)

typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackFreeMemory free;
    fmi2ComponentEnvironment env;
    char *name;
    Phase phase;

    int counter, start_counter, top, terminates;
    double step_height;
    char label[LABEL_SIZE];

    double time;         /* communication point reached */
    double next_stair;   /* the next whole second */
    double last_successful_time;
} Stair;

static void logf_(const Stair *s, fmi2Status status, const char *category, const char *format, ...)
    __attribute__((format(printf, 4, 5)));
static void logf_(const Stair *s, fmi2Status status, const char *category, const char *format, ...) {
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    s->logger(s->env, s->name, status, category, "%s", message);
}

/* Every function starts here: the call must be allowed in the current phase. */
static fmi2Status enter(Stair *s, const char *function, int allowed) {
    if (s == NULL) return fmi2Error;
    if (!(s->phase & allowed)) {
        logf_(s, fmi2Error, "logStatusError", "%s: illegal call sequence (phase %d)", function, (int)s->phase);
        return fmi2Error;
    }
    return fmi2OK;
}

#define ENTER(function, allowed)                                                                   \
    Stair *s = c;                                                                                  \
    do {                                                                                           \
        fmi2Status entered_ = enter(s, function, allowed);                                         \
        if (entered_ != fmi2OK) return entered_;                                                   \
    } while (0)

static int arrays_ok(Stair *s, const char *function, const fmi2ValueReference vr[], size_t n, const void *values) {
    if (n > 0 && (vr == NULL || values == NULL)) {
        logf_(s, fmi2Error, "logStatusError", "%s: NULL array for n = %zu", function, n);
        return 0;
    }
    return 1;
}

static fmi2Status unknown(Stair *s, const char *function, fmi2ValueReference vr) {
    logf_(s, fmi2Error, "logStatusError", "%s: no settable or gettable variable has value reference %u", function, vr);
    return fmi2Error;
}

static void reset_values(Stair *s) {
    s->counter = s->start_counter = 1;
    s->top = 10;
    s->terminates = 1;
    s->step_height = 1.0;
    strcpy(s->label, "stair");
    s->time = s->last_successful_time = 0.0;
    s->next_stair = 1.0;
}

/* ---- Inquire platform and version, logging ------------------------------ */

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    (void)on;
    (void)n;
    (void)categories;
    ENTER("fmi2SetDebugLogging", ANY);
    return fmi2OK; /* discards and errors are always logged */
}

/* ---- Creation and destruction --------------------------------------------- */

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                     const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                     fmi2Boolean logging_on) {
    (void)resources;
    (void)visible;
    (void)logging_on;
    if (functions == NULL || functions->logger == NULL || functions->allocateMemory == NULL ||
        functions->freeMemory == NULL || name == NULL || name[0] == '\0')
        return NULL;
    Stair probe = {.logger = functions->logger, .env = functions->componentEnvironment, .name = (char *)name};
    if (type != fmi2CoSimulation || guid == NULL || strcmp(guid, GUID) != 0) {
        logf_(&probe, fmi2Error, "logStatusError", "fmi2Instantiate: Stair is a co-simulation FMU with GUID %s", GUID);
        return NULL;
    }
    Stair *s = functions->allocateMemory(1, sizeof(Stair));
    char *copy = functions->allocateMemory(strlen(name) + 1, 1);
    if (s == NULL || copy == NULL) {
        functions->freeMemory(s);
        functions->freeMemory(copy);
        return NULL;
    }
    strcpy(copy, name);
    s->logger = functions->logger;
    s->free = functions->freeMemory;
    s->env = functions->componentEnvironment;
    s->name = copy;
    s->phase = INSTANTIATED;
    reset_values(s);
    return s;
}

/* A line to the file STAIR_TRACE names, if it names one: the call, the
 * phase, the time, then `detail`. */
static void trace(const Stair *s, const char *function, const char *detail) {
    const char *path = getenv("STAIR_TRACE");
    if (path == NULL) return;
    FILE *f = fopen(path, "a");
    if (f == NULL) return;
    fprintf(f, "%s phase=%d t=%g%s\n", function, (int)s->phase, s->time, detail);
    fclose(f);
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    Stair *s = c;
    if (s == NULL) return;
    trace(s, "fmi2FreeInstance", "");
    fmi2CallbackFreeMemory free_ = s->free;
    free_(s->name);
    free_(s);
}

/* ---- Initialization, termination, reset ----------------------------------- */

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                      fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    (void)tolerance_defined;
    (void)tolerance;
    ENTER("fmi2SetupExperiment", INSTANTIATED);
    if (!isfinite(start)) {
        logf_(s, fmi2Error, "logStatusError", "fmi2SetupExperiment: start time %g is not finite", start);
        return fmi2Error;
    }
    s->time = s->last_successful_time = start;
    s->next_stair = floor(start) + 1.0;
    char told[64];
    if (stop_defined) {
        snprintf(told, sizeof told, " stop=%g", stop);
    } else {
        snprintf(told, sizeof told, " stop=undefined");
    }
    trace(s, "fmi2SetupExperiment", told);
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    ENTER("fmi2EnterInitializationMode", INSTANTIATED);
    s->phase = INITIALIZATION;
    return fmi2OK;
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    ENTER("fmi2ExitInitializationMode", INITIALIZATION);
    if (s->top < 2 || !(s->step_height >= 0.0 && s->step_height <= 10.0)) {
        logf_(s, fmi2Error, "logStatusError", "fmi2ExitInitializationMode: top = %d or step_height = %g out of range",
              s->top, s->step_height);
        return fmi2Error;
    }
    s->start_counter = s->counter;
    s->phase = STEP_COMPLETE;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    ENTER("fmi2Terminate", STEP_COMPLETE | STEP_FAILED);
    trace(s, "fmi2Terminate", "");
    const char *fails = getenv("STAIR_TERMINATE_FAILS");
    if (fails != NULL) {
        logf_(s, fmi2Error, "logStatusError", "fmi2Terminate: %s", fails);
        s->phase = ERROR_STATE;
        return fmi2Error;
    }
    s->phase = TERMINATED;
    return fmi2OK;
}

EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    ENTER("fmi2Reset", ANY);
    reset_values(s);
    s->phase = INSTANTIATED;
    return fmi2OK;
}

/* ---- Getting and setting values ------------------------------------------- */

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    ENTER("fmi2GetReal", ANY);
    if (!arrays_ok(s, "fmi2GetReal", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_HEIGHT: value[i] = s->counter * s->step_height; break;
        case VR_STEP_HEIGHT: value[i] = s->step_height; break;
        case VR_END_TIME: value[i] = s->top - s->counter + floor(s->time); break;
        default: return unknown(s, "fmi2GetReal", vr[i]);
        }
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    ENTER("fmi2SetReal", BEFORE_STEPPING);
    if (!arrays_ok(s, "fmi2SetReal", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++)
        if (vr[i] != VR_STEP_HEIGHT) return unknown(s, "fmi2SetReal", vr[i]);
    for (size_t i = 0; i < n; i++) s->step_height = value[i];
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    ENTER("fmi2GetInteger", ANY);
    if (!arrays_ok(s, "fmi2GetInteger", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_COUNTER) value[i] = s->counter;
        else if (vr[i] == VR_TOP) value[i] = s->top;
        else return unknown(s, "fmi2GetInteger", vr[i]);
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    ENTER("fmi2SetInteger", BEFORE_STEPPING);
    if (!arrays_ok(s, "fmi2SetInteger", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++)
        if (vr[i] != VR_COUNTER && vr[i] != VR_TOP) return unknown(s, "fmi2SetInteger", vr[i]);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_COUNTER) s->counter = value[i];
        else s->top = value[i];
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    ENTER("fmi2GetBoolean", ANY);
    if (!arrays_ok(s, "fmi2GetBoolean", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_EVEN) value[i] = s->counter % 2 == 0 ? fmi2True : fmi2False;
        else if (vr[i] == VR_TERMINATES) value[i] = s->terminates ? fmi2True : fmi2False;
        else return unknown(s, "fmi2GetBoolean", vr[i]);
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    ENTER("fmi2SetBoolean", BEFORE_STEPPING);
    if (!arrays_ok(s, "fmi2SetBoolean", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++)
        if (vr[i] != VR_TERMINATES) return unknown(s, "fmi2SetBoolean", vr[i]);
    for (size_t i = 0; i < n; i++) s->terminates = value[i] != fmi2False;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    ENTER("fmi2GetString", ANY);
    if (!arrays_ok(s, "fmi2GetString", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_LABEL) return unknown(s, "fmi2GetString", vr[i]);
        value[i] = s->label;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    ENTER("fmi2SetString", BEFORE_STEPPING);
    if (!arrays_ok(s, "fmi2SetString", vr, n, value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_LABEL) return unknown(s, "fmi2SetString", vr[i]);
        if (value[i] == NULL || strlen(value[i]) >= LABEL_SIZE) {
            logf_(s, fmi2Error, "logStatusError", "fmi2SetString: label is NULL or longer than %d bytes", LABEL_SIZE - 1);
            return fmi2Error;
        }
    }
    for (size_t i = 0; i < n; i++) strcpy(s->label, value[i]);
    return fmi2OK;
}

/* ---- Optional capabilities, not provided ------------------------------------ */

static fmi2Status unsupported(fmi2Component c, const char *function) {
    ENTER(function, ANY);
    logf_(s, fmi2Error, "logStatusError", "%s: not supported (see the model description)", function);
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *f) { (void)f; return unsupported(c, "fmi2GetFMUstate"); }
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate f) { (void)f; return unsupported(c, "fmi2SetFMUstate"); }
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *f) { (void)f; return unsupported(c, "fmi2FreeFMUstate"); }
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate f, size_t *size) {
    (void)f;
    (void)size;
    return unsupported(c, "fmi2SerializedFMUstateSize");
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate f, fmi2Byte bytes[], size_t size) {
    (void)f;
    (void)bytes;
    (void)size;
    return unsupported(c, "fmi2SerializeFMUstate");
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *f) {
    (void)bytes;
    (void)size;
    (void)f;
    return unsupported(c, "fmi2DeSerializeFMUstate");
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
    return unsupported(c, "fmi2GetDirectionalDerivative");
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                              const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)n;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives");
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                               const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)n;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { return unsupported(c, "fmi2CancelStep"); }

/* ---- Stepping --------------------------------------------------------------- */

/* Climb the stairs of the whole seconds up to t + h (to a relative 1e-9,
 * so that a communication point counted as 90 * 0.1 reaches t = 9); at the
 * top, stop at that second and end the simulation (fmi2Discard). */
EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    (void)no_prior;
    ENTER("fmi2DoStep", STEP_COMPLETE);
    double tolerance = 1e-9 * fmax(1.0, fabs(s->time));
    if (!(h > 0) || !isfinite(h) || !(fabs(t - s->time) <= tolerance)) {
        logf_(s, fmi2Error, "logStatusError",
              "fmi2DoStep: step from %.17g over %g, but the FMU is at t = %.17g", t, h, s->time);
        s->phase = ERROR_STATE;
        return fmi2Error;
    }
    double end = t + h;
    while (s->next_stair <= end + 1e-9 * fmax(1.0, fabs(end))) {
        s->counter++;
        s->time = s->last_successful_time = s->next_stair;
        s->next_stair += 1.0;
        if (s->counter >= s->top) {
            s->phase = STEP_FAILED;
            logf_(s, fmi2Discard, "logStatusDiscard",
                  "fmi2DoStep: the top (counter = %d) is reached at t = %.17g: %s", s->counter, s->time,
                  s->terminates ? "the simulation ends (fmi2Terminated = true)" : "the step is discarded");
            return fmi2Discard;
        }
    }
    s->time = s->last_successful_time = end;
    return fmi2OK;
}

/* ---- Status (synchronous steps only) ---------------------------------------- */

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Status *value) {
    (void)kind;
    (void)value;
    ENTER("fmi2GetStatus", STATUS_PHASES);
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real *value) {
    ENTER("fmi2GetRealStatus", STATUS_PHASES);
    if (kind != fmi2LastSuccessfulTime || value == NULL) return fmi2Discard;
    *value = s->last_successful_time;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Integer *value) {
    (void)kind;
    (void)value;
    ENTER("fmi2GetIntegerStatus", STATUS_PHASES);
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Boolean *value) {
    ENTER("fmi2GetBooleanStatus", STATUS_PHASES);
    if (kind != fmi2Terminated || value == NULL) return fmi2Discard;
    *value = s->phase == STEP_FAILED && s->terminates ? fmi2True : fmi2False;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind kind, fmi2String *value) {
    (void)kind;
    (void)value;
    ENTER("fmi2GetStringStatus", STATUS_PHASES);
    return fmi2Discard;
}
