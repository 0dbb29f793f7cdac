/* A minimal FMI 2.0 Co-Simulation FMU in C, compiled by the tests with `cc`
 * to exercise the importer against a binary that is not ours: y = 2·u.
 *
 *   -DSTUB_ONLY_GET_VERSION  export fmi2GetVersion only
 *   -DSTUB_VERSION='"3.0"'   what fmi2GetVersion returns (default "2.0")
 *
 * Behaviour the tests rely on:
 *   - fmi2Instantiate fails (NULL, logged) unless the GUID is "{stub}";
 *   - fmi2SetReal refuses NaN for u with a formatted error message;
 *   - u = 12345 logs a 3000-character warning ending in "END";
 *   - fmi2DoStep with h <= 0 returns fmi2Discard, with u = -1 fmi2Fatal;
 *   - stub_live_instances() counts instances not yet freed;
 *   - stub_steps(flag) counts the fmi2DoStep calls whose
 *     noSetFMUStatePriorToCurrentPoint was true (flag 1) or false (0). */

#include <math.h>
#include <stddef.h>
#include <string.h>

#ifndef STUB_VERSION
#define STUB_VERSION "2.0"
#endif

#define EXPORT __attribute__((visibility("default")))

EXPORT const char *fmi2GetVersion(void) { return STUB_VERSION; }

#ifndef STUB_ONLY_GET_VERSION

typedef void (*Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;

typedef struct {
    Callbacks cb;
    char name[64];
    double u, y, t;
} Stub;

enum { OK = 0, WARNING = 1, DISCARD = 2, ERROR = 3, FATAL = 4 };

static int live = 0;

EXPORT int stub_live_instances(void) { return live; }

static int steps_by_flag[2] = {0, 0};

EXPORT int stub_steps(int no_prior) { return steps_by_flag[no_prior != 0]; }

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }

EXPORT void *fmi2Instantiate(const char *name, int type, const char *guid, const char *resources,
                             const Callbacks *cb, int visible, int logging_on) {
    (void)resources; (void)visible; (void)logging_on;
    if (type != 1 || strcmp(guid, "{stub}") != 0) {
        cb->logger(cb->env, name, ERROR, "logError", "fmi2Instantiate: wrong GUID %s or type %d", guid, type);
        return NULL;
    }
    Stub *s = cb->allocate(1, sizeof(Stub));
    s->cb = *cb;
    strncpy(s->name, name, sizeof s->name - 1);
    live++;
    return s;
}

EXPORT void fmi2FreeInstance(void *c) {
    Stub *s = c;
    live--;
    s->cb.free(s);
}

EXPORT int fmi2SetDebugLogging(void *c, int on, size_t n, const char *const *cats) {
    (void)c; (void)on; (void)n; (void)cats;
    return OK;
}

EXPORT int fmi2SetupExperiment(void *c, int tol_defined, double tol, double start, int stop_defined, double stop) {
    (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
    ((Stub *)c)->t = start;
    return OK;
}

EXPORT int fmi2EnterInitializationMode(void *c) { (void)c; return OK; }
EXPORT int fmi2ExitInitializationMode(void *c) { (void)c; return OK; }
EXPORT int fmi2Terminate(void *c) { (void)c; return OK; }
EXPORT int fmi2Reset(void *c) { Stub *s = c; s->u = s->y = s->t = 0; return OK; }
EXPORT int fmi2CancelStep(void *c) { (void)c; return ERROR; }

EXPORT int fmi2GetReal(void *c, const unsigned *vr, size_t n, double *v) {
    Stub *s = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 0) v[i] = s->u;
        else if (vr[i] == 1) v[i] = s->y;
        else {
            s->cb.logger(s->cb.env, s->name, ERROR, "logError", "fmi2GetReal: unknown value reference %u", vr[i]);
            return ERROR;
        }
    }
    return OK;
}

EXPORT int fmi2SetReal(void *c, const unsigned *vr, size_t n, const double *v) {
    Stub *s = c;
    int status = OK;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 0) {
            s->cb.logger(s->cb.env, s->name, ERROR, "logError", "fmi2SetReal: cannot set value reference %u", vr[i]);
            return ERROR;
        }
        if (isnan(v[i])) {
            s->cb.logger(s->cb.env, s->name, ERROR, "logError", "fmi2SetReal: %s (vr %u) must not be NaN", "u", vr[i]);
            return ERROR;
        }
        if (v[i] == 12345.0) {
            char big[3001];
            memset(big, 'x', 2997);
            strcpy(big + 2997, "END");
            s->cb.logger(s->cb.env, s->name, WARNING, "logWarning", "%s", big);
            status = WARNING;
        }
        s->u = v[i];
    }
    return status;
}

EXPORT int fmi2GetInteger(void *c, const unsigned *vr, size_t n, int *v) { (void)c; (void)vr; (void)v; return n ? ERROR : OK; }
EXPORT int fmi2SetInteger(void *c, const unsigned *vr, size_t n, const int *v) { (void)c; (void)vr; (void)v; return n ? ERROR : OK; }
EXPORT int fmi2GetBoolean(void *c, const unsigned *vr, size_t n, int *v) { (void)c; (void)vr; (void)v; return n ? ERROR : OK; }
EXPORT int fmi2SetBoolean(void *c, const unsigned *vr, size_t n, const int *v) { (void)c; (void)vr; (void)v; return n ? ERROR : OK; }
EXPORT int fmi2GetString(void *c, const unsigned *vr, size_t n, const char **v) { (void)c; (void)vr; (void)v; return n ? ERROR : OK; }
EXPORT int fmi2SetString(void *c, const unsigned *vr, size_t n, const char *const *v) { (void)c; (void)vr; (void)v; return n ? ERROR : OK; }

EXPORT int fmi2DoStep(void *c, double t, double h, int no_prior) {
    Stub *s = c;
    steps_by_flag[no_prior != 0]++;
    if (!(h > 0)) {
        s->cb.logger(s->cb.env, s->name, DISCARD, "logWarning", "fmi2DoStep: step size h = %g must be > 0", h);
        return DISCARD;
    }
    if (s->u == -1.0) {
        s->cb.logger(s->cb.env, s->name, FATAL, "logError", "fmi2DoStep: u = -1 breaks everything");
        return FATAL;
    }
    s->t = t + h;
    s->y = 2 * s->u;
    return OK;
}

EXPORT int fmi2GetStatus(void *c, int kind, int *v) { (void)c; (void)kind; (void)v; return DISCARD; }
EXPORT int fmi2GetRealStatus(void *c, int kind, double *v) { *v = ((Stub *)c)->t; (void)kind; return OK; }
EXPORT int fmi2GetIntegerStatus(void *c, int kind, int *v) { (void)c; (void)kind; (void)v; return DISCARD; }
EXPORT int fmi2GetBooleanStatus(void *c, int kind, int *v) { (void)c; (void)kind; *v = 0; return OK; }
EXPORT int fmi2GetStringStatus(void *c, int kind, const char **v) { (void)c; (void)kind; (void)v; return DISCARD; }

#endif
