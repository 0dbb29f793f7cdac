/* fmi3_fmu.h: the part of a hand-written FMI 3.0 Co-Simulation test FMU
 * that is not its model: the C types of FMI 3.0.1 §2.2 (as much as is
 * used), the phases of its state machine, logging, the check every call
 * starts with, and stand-ins for the FMI 3.0 functions these FMUs do not
 * offer (Model Exchange, Scheduled Execution, clocks, the types they have
 * no variables of), each of which logs why and returns fmi3Error.
 *
 * A model file (bouncing_ball.c, stair.c in this folder) defines
 * MODEL_IDENTIFIER and INSTANTIATION_TOKEN before including this header
 * (and OFFERS_EVERY_TYPE if it has variables of every type, feedthrough.c),
 * and a struct `Model` whose first member is a `Base`; the functions every
 * model writes alike are the macros at the end (COMMON_FUNCTIONS,
 * STATE_FUNCTIONS). Written for the
 * tests of fricsim against the FMI 3.0 standard; both fricsim and FMPy
 * import them. */

#ifndef FMI3_FMU_H
#define FMI3_FMU_H

#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi3Instance;
typedef void *fmi3InstanceEnvironment;
typedef void *fmi3FMUState;
typedef uint32_t fmi3ValueReference;
typedef float fmi3Float32;
typedef double fmi3Float64;
typedef int8_t fmi3Int8;
typedef uint8_t fmi3UInt8;
typedef int16_t fmi3Int16;
typedef uint16_t fmi3UInt16;
typedef int32_t fmi3Int32;
typedef uint32_t fmi3UInt32;
typedef int64_t fmi3Int64;
typedef uint64_t fmi3UInt64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char *fmi3String;
typedef uint8_t fmi3Byte;
typedef const fmi3Byte *fmi3Binary;
typedef bool fmi3Clock;

typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;

typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment, fmi3Float64, fmi3Boolean,
                                               fmi3Boolean, fmi3Boolean, fmi3Boolean, fmi3Boolean *,
                                               fmi3Float64 *);
typedef void (*fmi3ClockUpdateCallback)(fmi3InstanceEnvironment);
typedef void (*fmi3LockPreemptionCallback)(void);
typedef void (*fmi3UnlockPreemptionCallback)(void);

#define EXPORT __attribute__((visibility("default")))

typedef enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION = 1 << 1,
    STEP_MODE = 1 << 2,
    TERMINATED = 1 << 3,
    FAILED = 1 << 4
} Phase;

#define ANY (INSTANTIATED | INITIALIZATION | STEP_MODE | TERMINATED | FAILED)
#define SETTABLE (INSTANTIATED | INITIALIZATION)
#define GETTABLE (INITIALIZATION | STEP_MODE | TERMINATED | FAILED)

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    char name[128];
    Phase phase;
} Base;

static void logf_(const Base *b, fmi3Status status, const char *category, const char *format, ...)
    __attribute__((format(printf, 4, 5)));
static void logf_(const Base *b, fmi3Status status, const char *category, const char *format, ...) {
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (b->log != NULL) b->log(b->env, status, category, message);
}

/* An error: logged, and the instance fails (FMI 3.0.1 §2.3.4: after
 * fmi3Error only reset and free are allowed). */
static fmi3Status fail(Base *b, const char *format, ...) __attribute__((format(printf, 2, 3)));
static fmi3Status fail(Base *b, const char *format, ...) {
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (b->log != NULL) b->log(b->env, fmi3Error, "logStatusError", message);
    b->phase = FAILED;
    return fmi3Error;
}

/* Every function starts here: a live instance, in a phase that allows the call. */
#define ENTER(function, allowed)                                                                   \
    Model *m = (Model *)instance;                                                                  \
    if (m == NULL) return fmi3Error;                                                               \
    if (!(m->base.phase & (allowed)))                                                              \
        return fail(&m->base, "%s: not allowed in phase %d", function, (int)m->base.phase);

/* The arrays of a get or set call: not NULL, and one value per scalar. */
#define ARRAYS(function, values)                                                                   \
    if (nValueReferences > 0 && (valueReferences == NULL || (values) == NULL))                     \
        return fail(&m->base, "%s: NULL array", function);                                         \
    if (nValues != nValueReferences)                                                               \
        return fail(&m->base, "%s: nValues = %zu for %zu scalars", function, nValues,              \
                    nValueReferences);

/* ---- Functions these FMUs do not offer --------------------------------- */

/* (their arguments are not read) */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"

#define NOT_OFFERED(function, ...)                                                                 \
    EXPORT fmi3Status function(fmi3Instance instance, __VA_ARGS__) {                               \
        Base *b = (Base *)instance;                                                                \
        if (b == NULL) return fmi3Error;                                                           \
        return fail(b, #function " is not offered by " MODEL_IDENTIFIER);                          \
    }

#define NOT_OFFERED_0(function)                                                                    \
    EXPORT fmi3Status function(fmi3Instance instance) {                                            \
        Base *b = (Base *)instance;                                                                \
        if (b == NULL) return fmi3Error;                                                           \
        return fail(b, #function " is not offered by " MODEL_IDENTIFIER);                          \
    }

#define NOT_OFFERED_GET_SET(Type)                                                                  \
    NOT_OFFERED(fmi3Get##Type, const fmi3ValueReference vr[], size_t n, fmi3##Type v[], size_t nv) \
    NOT_OFFERED(fmi3Set##Type, const fmi3ValueReference vr[], size_t n, const fmi3##Type v[],      \
                size_t nv)

/* (a model with variables of these types defines OFFERS_EVERY_TYPE
 * before including this header, and the functions itself) */
#ifndef OFFERS_EVERY_TYPE
NOT_OFFERED_GET_SET(Float32)
NOT_OFFERED_GET_SET(Int8)
NOT_OFFERED_GET_SET(UInt8)
NOT_OFFERED_GET_SET(Int16)
NOT_OFFERED_GET_SET(UInt16)
NOT_OFFERED_GET_SET(UInt32)
NOT_OFFERED_GET_SET(Int64)
NOT_OFFERED_GET_SET(UInt64)
#endif
NOT_OFFERED(fmi3GetBinary, const fmi3ValueReference vr[], size_t n, size_t sizes[], fmi3Binary v[],
            size_t nv)
NOT_OFFERED(fmi3SetBinary, const fmi3ValueReference vr[], size_t n, const size_t sizes[],
            const fmi3Binary v[], size_t nv)
NOT_OFFERED(fmi3GetClock, const fmi3ValueReference vr[], size_t n, fmi3Clock v[])
NOT_OFFERED(fmi3SetClock, const fmi3ValueReference vr[], size_t n, const fmi3Clock v[])
NOT_OFFERED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference vr, size_t *n)
NOT_OFFERED(fmi3GetVariableDependencies, fmi3ValueReference dependent, size_t e[],
            fmi3ValueReference independents[], size_t ki[], int kinds[], size_t n)
NOT_OFFERED(fmi3GetAdjointDerivative, const fmi3ValueReference u[], size_t nu,
            const fmi3ValueReference k[], size_t nk, const fmi3Float64 seed[], size_t ns,
            fmi3Float64 s[], size_t nsens)
NOT_OFFERED(fmi3GetOutputDerivatives, const fmi3ValueReference vr[], size_t n,
            const fmi3Int32 orders[], fmi3Float64 v[], size_t nv)
NOT_OFFERED_0(fmi3EnterEventMode)
NOT_OFFERED_0(fmi3EnterStepMode)
NOT_OFFERED_0(fmi3EnterConfigurationMode)
NOT_OFFERED_0(fmi3ExitConfigurationMode)
NOT_OFFERED_0(fmi3EvaluateDiscreteStates)
NOT_OFFERED(fmi3UpdateDiscreteStates, fmi3Boolean *a, fmi3Boolean *b_, fmi3Boolean *c,
            fmi3Boolean *d, fmi3Boolean *e, fmi3Float64 *f)

/* clocks (§2.3.6) */
NOT_OFFERED(fmi3GetIntervalDecimal, const fmi3ValueReference vr[], size_t n, fmi3Float64 intervals[],
            int qualifiers[])
NOT_OFFERED(fmi3GetIntervalFraction, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
            fmi3UInt64 resolutions[], int qualifiers[])
NOT_OFFERED(fmi3GetShiftDecimal, const fmi3ValueReference vr[], size_t n, fmi3Float64 shifts[])
NOT_OFFERED(fmi3GetShiftFraction, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
            fmi3UInt64 resolutions[])
NOT_OFFERED(fmi3SetIntervalDecimal, const fmi3ValueReference vr[], size_t n, const fmi3Float64 intervals[])
NOT_OFFERED(fmi3SetIntervalFraction, const fmi3ValueReference vr[], size_t n,
            const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
NOT_OFFERED(fmi3SetShiftDecimal, const fmi3ValueReference vr[], size_t n, const fmi3Float64 shifts[])
NOT_OFFERED(fmi3SetShiftFraction, const fmi3ValueReference vr[], size_t n,
            const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
/* Model Exchange (§3.2) */
NOT_OFFERED_0(fmi3EnterContinuousTimeMode)
NOT_OFFERED(fmi3CompletedIntegratorStep, fmi3Boolean no_set_prior, fmi3Boolean *enter_event_mode,
            fmi3Boolean *terminate)
NOT_OFFERED(fmi3SetTime, fmi3Float64 time)
NOT_OFFERED(fmi3SetContinuousStates, const fmi3Float64 x[], size_t n)
NOT_OFFERED(fmi3GetContinuousStateDerivatives, fmi3Float64 dx[], size_t n)
NOT_OFFERED(fmi3GetEventIndicators, fmi3Float64 z[], size_t n)
NOT_OFFERED(fmi3GetContinuousStates, fmi3Float64 x[], size_t n)
NOT_OFFERED(fmi3GetNominalsOfContinuousStates, fmi3Float64 nominals[], size_t n)
NOT_OFFERED(fmi3GetNumberOfEventIndicators, size_t *n)
NOT_OFFERED(fmi3GetNumberOfContinuousStates, size_t *n)
/* Scheduled Execution (§5.2) */
NOT_OFFERED(fmi3ActivateModelPartition, fmi3ValueReference clock, fmi3Float64 time)

#pragma GCC diagnostic pop

EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
                                                 fmi3Boolean visible, fmi3Boolean logging,
                                                 fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    (void)token, (void)resources, (void)visible, (void)logging;
    if (log != NULL)
        log(env, fmi3Error, "logStatusError", MODEL_IDENTIFIER " is a Co-Simulation FMU only");
    (void)name;
    return NULL;
}

EXPORT fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible, fmi3Boolean logging,
    fmi3InstanceEnvironment env, fmi3LogMessageCallback log, fmi3ClockUpdateCallback clock,
    fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock) {
    (void)name, (void)token, (void)resources, (void)visible, (void)logging, (void)clock, (void)lock,
        (void)unlock;
    if (log != NULL)
        log(env, fmi3Error, "logStatusError", MODEL_IDENTIFIER " is a Co-Simulation FMU only");
    return NULL;
}

EXPORT const char *fmi3GetVersion(void) { return "3.0"; }

/* Checks the arguments every instantiation shares and fills the base;
 * NULL (logged) when they are wrong. */
static void *instantiate_base(size_t size, fmi3String name, fmi3String token, fmi3Boolean event_mode,
                              fmi3Boolean early_return, fmi3InstanceEnvironment env,
                              fmi3LogMessageCallback log) {
    Base probe = {.env = env, .log = log};
    if (name == NULL || name[0] == '\0' || strlen(name) >= sizeof probe.name) {
        logf_(&probe, fmi3Error, "logStatusError", "fmi3InstantiateCoSimulation: bad instance name");
        return NULL;
    }
    if (token == NULL || strcmp(token, INSTANTIATION_TOKEN) != 0) {
        logf_(&probe, fmi3Error, "logStatusError",
              "fmi3InstantiateCoSimulation: the instantiation token of " MODEL_IDENTIFIER " is %s",
              INSTANTIATION_TOKEN);
        return NULL;
    }
    if (event_mode || early_return) {
        logf_(&probe, fmi3Error, "logStatusError",
              "fmi3InstantiateCoSimulation: " MODEL_IDENTIFIER " has no event mode and no early return");
        return NULL;
    }
    Base *b = calloc(1, size);
    if (b == NULL) return NULL;
    b->env = env;
    b->log = log;
    strcpy(b->name, name);
    b->phase = INSTANTIATED;
    return b;
}

/* ---- What every model of these FMUs defines the same way ---------------- */

/* fmi3InstantiateCoSimulation, fmi3FreeInstance and fmi3SetDebugLogging of
 * a `Model` whose fields are set to their start values by
 * `reset_values(Model *)`. */
#define COMMON_FUNCTIONS(reset_values)                                                             \
    EXPORT fmi3Instance fmi3InstantiateCoSimulation(                                               \
        fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,              \
        fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_return,                     \
        const fmi3ValueReference required[], size_t n_required, fmi3InstanceEnvironment env,       \
        fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {                       \
        (void)resources, (void)visible, (void)logging, (void)required, (void)n_required,           \
            (void)update;                                                                          \
        Model *m = instantiate_base(sizeof(Model), name, token, event_mode, early_return, env, log); \
        if (m != NULL) reset_values(m);                                                            \
        return m;                                                                                  \
    }                                                                                              \
    EXPORT void fmi3FreeInstance(fmi3Instance instance) { free(instance); }                        \
    EXPORT fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean on, size_t n,         \
                                          const fmi3String c[]) {                                  \
        (void)on, (void)n, (void)c;                                                                \
        ENTER("fmi3SetDebugLogging", ANY);                                                         \
        return fmi3OK; /* errors are always logged */                                              \
    }

/* fmi3GetFMUState, fmi3SetFMUState and fmi3FreeFMUState of a `Model` whose
 * member `s` (a plain struct) is all its state: a state is a copy of it. */
#define STATE_FUNCTIONS                                                                            \
    EXPORT fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {                \
        ENTER("fmi3GetFMUState", GETTABLE | INSTANTIATED);                                         \
        if (state == NULL) return fail(&m->base, "fmi3GetFMUState: NULL");                         \
        if (*state == NULL) *state = malloc(sizeof m->s);                                          \
        if (*state == NULL) return fail(&m->base, "fmi3GetFMUState: out of memory");               \
        memcpy(*state, &m->s, sizeof m->s);                                                        \
        return fmi3OK;                                                                             \
    }                                                                                              \
    EXPORT fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {                 \
        ENTER("fmi3SetFMUState", GETTABLE | INSTANTIATED);                                         \
        if (state == NULL) return fail(&m->base, "fmi3SetFMUState: NULL");                         \
        memcpy(&m->s, state, sizeof m->s);                                                         \
        return fmi3OK;                                                                             \
    }                                                                                              \
    EXPORT fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {               \
        ENTER("fmi3FreeFMUState", ANY);                                                            \
        if (state == NULL) return fail(&m->base, "fmi3FreeFMUState: NULL");                        \
        free(*state);                                                                              \
        *state = NULL;                                                                             \
        return fmi3OK;                                                                             \
    }

#endif
