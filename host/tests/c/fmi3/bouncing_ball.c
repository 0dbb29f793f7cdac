/* BouncingBall: a ball dropped from height h0 that bounces on the floor,
 * as a complete FMI 3.0 Co-Simulation FMU written by hand in C (like the
 * Modelica Reference FMU BouncingBall, with the same physics), with its
 * own bouncing_ball.xml beside this file.
 *
 *   h' = v, v' = -g; at h = 0 with v < 0: v := -e·v (a bounce);
 *   once a bounce leaves less than v_min the ball rests (h = v = 0).
 *
 * fmi3DoStep integrates the flight in closed form (a parabola) and finds
 * each bounce inside the step from the root of h0 + v·τ - g·τ²/2 = 0, so
 * the result does not depend on the communication step: the tests compare
 * it with the closed form and with FMPy's run of the same FMU. Outputs:
 * h, v (Float64), bounces (Int32), resting (Boolean); parameters g, e,
 * v_min, label (String). The FMU state can be got, set and serialized. */

#define MODEL_IDENTIFIER "BouncingBall"
#define INSTANTIATION_TOKEN "{1f3e5a7c-9b2d-4e6f-8a0c-2d4f6b8e0a1c}"
#include "fmi3_fmu.h"

enum { VR_TIME, VR_H, VR_V, VR_G, VR_E, VR_V_MIN, VR_BOUNCES, VR_RESTING, VR_LABEL };

#define LABEL_SIZE 64

/* What an FMU state holds: everything but the base. */
typedef struct {
    double time, h, v, g, e, v_min;
    int32_t bounces;
    bool resting;
    char label[LABEL_SIZE];
} State;

typedef struct {
    Base base;
    State s;
} Model;

static void reset_values(Model *m) {
    State *s = &m->s;
    *s = (State){.time = 0.0, .h = 1.0, .v = 0.0, .g = 9.81, .e = 0.7, .v_min = 0.1};
    strcpy(s->label, "ball");
}

COMMON_FUNCTIONS(reset_values)

static fmi3Status check_parameters(Model *m) {
    State *s = &m->s;
    if (!(s->g > 0.0) || !isfinite(s->g)) return fail(&m->base, "g = %g: must be positive", s->g);
    if (!(s->e >= 0.0 && s->e <= 1.0)) return fail(&m->base, "e = %g: must be in [0, 1]", s->e);
    if (!(s->v_min >= 0.0) || !isfinite(s->v_min)) return fail(&m->base, "v_min = %g: must be >= 0", s->v_min);
    if (!(s->h >= 0.0) || !isfinite(s->h)) return fail(&m->base, "h = %g: must be >= 0", s->h);
    return fmi3OK;
}

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolerance_defined,
                                              fmi3Float64 tolerance, fmi3Float64 start,
                                              fmi3Boolean stop_defined, fmi3Float64 stop) {
    (void)tolerance_defined, (void)tolerance, (void)stop_defined, (void)stop;
    ENTER("fmi3EnterInitializationMode", INSTANTIATED);
    if (!isfinite(start)) return fail(&m->base, "fmi3EnterInitializationMode: startTime = %g", start);
    m->s.time = start;
    m->base.phase = INITIALIZATION;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ENTER("fmi3ExitInitializationMode", INITIALIZATION);
    fmi3Status status = check_parameters(m);
    if (status != fmi3OK) return status;
    m->base.phase = STEP_MODE;
    return fmi3OK;
}

EXPORT fmi3Status fmi3Terminate(fmi3Instance instance) {
    ENTER("fmi3Terminate", STEP_MODE);
    m->base.phase = TERMINATED;
    return fmi3OK;
}

EXPORT fmi3Status fmi3Reset(fmi3Instance instance) {
    ENTER("fmi3Reset", ANY);
    reset_values(m);
    m->base.phase = INSTANTIATED;
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3GetFloat64", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetFloat64", values);
    const State *s = &m->s;
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_TIME: values[i] = s->time; break;
        case VR_H: values[i] = s->h; break;
        case VR_V: values[i] = s->v; break;
        case VR_G: values[i] = s->g; break;
        case VR_E: values[i] = s->e; break;
        case VR_V_MIN: values[i] = s->v_min; break;
        default: return fail(&m->base, "fmi3GetFloat64: no Float64 variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3SetFloat64", SETTABLE);
    ARRAYS("fmi3SetFloat64", values);
    State *s = &m->s;
    for (size_t i = 0; i < nValueReferences; i++) {
        if (!isfinite(values[i]))
            return fail(&m->base, "fmi3SetFloat64: value reference %u set to %g", valueReferences[i], values[i]);
        switch (valueReferences[i]) {
        case VR_H: s->h = values[i]; break;
        case VR_V: s->v = values[i]; break;
        case VR_G: s->g = values[i]; break;
        case VR_E: s->e = values[i]; break;
        case VR_V_MIN: s->v_min = values[i]; break;
        default: return fail(&m->base, "fmi3SetFloat64: no settable Float64 variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Int32 values[], size_t nValues) {
    ENTER("fmi3GetInt32", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetInt32", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] != VR_BOUNCES)
            return fail(&m->base, "fmi3GetInt32: no Int32 variable has value reference %u", valueReferences[i]);
        values[i] = m->s.bounces;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Int32 values[], size_t nValues) {
    ENTER("fmi3SetInt32", SETTABLE);
    ARRAYS("fmi3SetInt32", values);
    if (nValueReferences > 0)
        return fail(&m->base, "fmi3SetInt32: no settable Int32 variable has value reference %u", valueReferences[0]);
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Boolean values[], size_t nValues) {
    ENTER("fmi3GetBoolean", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetBoolean", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] != VR_RESTING)
            return fail(&m->base, "fmi3GetBoolean: no Boolean variable has value reference %u", valueReferences[i]);
        values[i] = m->s.resting;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Boolean values[], size_t nValues) {
    ENTER("fmi3SetBoolean", SETTABLE);
    ARRAYS("fmi3SetBoolean", values);
    if (nValueReferences > 0)
        return fail(&m->base, "fmi3SetBoolean: no settable Boolean variable has value reference %u", valueReferences[0]);
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3String values[], size_t nValues) {
    ENTER("fmi3GetString", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetString", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] != VR_LABEL)
            return fail(&m->base, "fmi3GetString: no String variable has value reference %u", valueReferences[i]);
        values[i] = m->s.label;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3String values[], size_t nValues) {
    ENTER("fmi3SetString", SETTABLE);
    ARRAYS("fmi3SetString", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] != VR_LABEL)
            return fail(&m->base, "fmi3SetString: no String variable has value reference %u", valueReferences[i]);
        if (values[i] == NULL || strlen(values[i]) >= LABEL_SIZE)
            return fail(&m->base, "fmi3SetString: label must be a string shorter than %d bytes", LABEL_SIZE);
        strcpy(m->s.label, values[i]);
    }
    return fmi3OK;
}

/* The flight over `dt` in closed form, with every bounce in it. */
static void fly(State *s, double dt) {
    double remaining = dt;
    while (remaining > 0.0 && !s->resting) {
        /* the first τ > 0 with h + v·τ - g·τ²/2 = 0 */
        double tau = (s->v + sqrt(s->v * s->v + 2.0 * s->g * s->h)) / s->g;
        if (tau > remaining) {
            s->h += s->v * remaining - 0.5 * s->g * remaining * remaining;
            s->v -= s->g * remaining;
            remaining = 0.0;
        } else {
            double impact = s->v - s->g * tau;
            s->h = 0.0;
            s->v = -s->e * impact;
            s->bounces += 1;
            remaining -= tau;
            if (s->v < s->v_min) {
                s->resting = true;
                s->v = 0.0;
            }
        }
    }
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 dt,
                             fmi3Boolean no_set_prior, fmi3Boolean *event_handling_needed,
                             fmi3Boolean *terminate, fmi3Boolean *early_return, fmi3Float64 *last_time) {
    (void)no_set_prior;
    ENTER("fmi3DoStep", STEP_MODE);
    if (event_handling_needed == NULL || terminate == NULL || early_return == NULL || last_time == NULL)
        return fail(&m->base, "fmi3DoStep: NULL out-pointer");
    if (!(dt > 0.0) || !isfinite(dt)) return fail(&m->base, "fmi3DoStep: communicationStepSize = %g", dt);
    if (fabs(t - m->s.time) > 1e-9 * fmax(1.0, fabs(t)))
        return fail(&m->base, "fmi3DoStep: currentCommunicationPoint = %.17g, but the FMU is at %.17g", t, m->s.time);
    fly(&m->s, dt);
    m->s.time = t + dt;
    *event_handling_needed = false;
    *terminate = false;
    *early_return = false;
    *last_time = m->s.time;
    return fmi3OK;
}

/* ---- FMU state ------------------------------------------------------------ */

STATE_FUNCTIONS

EXPORT fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t *size) {
    ENTER("fmi3SerializedFMUStateSize", ANY);
    if (state == NULL || size == NULL) return fail(&m->base, "fmi3SerializedFMUStateSize: NULL");
    *size = sizeof(State);
    return fmi3OK;
}

EXPORT fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state, fmi3Byte bytes[], size_t size) {
    ENTER("fmi3SerializeFMUState", ANY);
    if (state == NULL || bytes == NULL || size != sizeof(State))
        return fail(&m->base, "fmi3SerializeFMUState: NULL, or %zu bytes for a state of %zu", size, sizeof(State));
    memcpy(bytes, state, sizeof(State));
    return fmi3OK;
}

EXPORT fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte bytes[], size_t size,
                                          fmi3FMUState *state) {
    ENTER("fmi3DeserializeFMUState", ANY);
    if (bytes == NULL || state == NULL || size != sizeof(State))
        return fail(&m->base, "fmi3DeserializeFMUState: NULL, or %zu bytes for a state of %zu", size, sizeof(State));
    if (*state == NULL) *state = malloc(sizeof(State));
    if (*state == NULL) return fail(&m->base, "fmi3DeserializeFMUState: out of memory");
    memcpy(*state, bytes, sizeof(State));
    return fmi3OK;
}

#pragma GCC diagnostic ignored "-Wunused-parameter"
NOT_OFFERED(fmi3GetDirectionalDerivative, const fmi3ValueReference u[], size_t nu,
            const fmi3ValueReference k[], size_t nk, const fmi3Float64 seed[], size_t ns,
            fmi3Float64 s[], size_t nsens)
