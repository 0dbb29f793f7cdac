/* SpringMass: a mass pulled through a spring by a point moving at a
 * constant speed, with a friction force as its input, as a complete FMI
 * 3.0 Co-Simulation FMU written by hand in C, with its own
 * spring_mass.xml beside this file. It is the rig of the stick-slip
 * benchmark of Canudas de Wit et al. 1995 (the plain mode of this
 * repository's Rig1D.fmu, which is FMI 2.0), written independently for
 * the tests of systems that mix FMI 3.0 and FMI 2.0 FMUs:
 *
 *   m·ẍ = k·(x_a0 + v_a·t − x) − F,     input F (the friction force)
 *
 * fmi3DoStep integrates it exactly for F held over the step: with
 * ω² = k/m and x_eq(t) = x_a0 + v_a·t − F/k (where the spring balances
 * F while the point moves), y = x − x_eq oscillates freely:
 *   y(t+h) = y·cos ωh + ((ẋ − v_a)/ω)·sin ωh.
 * The step's sensitivity to F is its directional derivative (as the
 * strong-coupling masters ask of an FMU after a step):
 *   ∂x/∂F = −(1 − cos ωh)/k,   ∂v/∂F = −sin(ωh)/(m·ω);
 * before any step, or once F is set again, it is the direct feedthrough,
 * which is none. Outputs x and v; FMU state got, set and serialized. */

#define MODEL_IDENTIFIER "SpringMass"
#define INSTANTIATION_TOKEN "{3c5e7a9b-2d4f-4a6c-8e0b-1f3d5b7c9e2a}"
#include "fmi3_fmu.h"

enum { VR_TIME, VR_X, VR_V, VR_F, VR_M, VR_K, VR_X_A0, VR_V_A, VR_X0, VR_V0 };

/* What an FMU state holds: everything but the base. */
typedef struct {
    double time, x, v, force, m, k, x_a0, v_a, x0, v0;
    double last_h; /* the last step's size */
    int stepped;   /* a step was made and F not set since */
} State;

typedef struct {
    Base base;
    State s;
} Model;

static void reset_values(Model *m) {
    m->s = (State){.m = 1.0, .k = 2.0, .x_a0 = 0.0, .v_a = 0.1};
}

COMMON_FUNCTIONS(reset_values)

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
    State *s = &m->s;
    if (!(s->m > 0.0)) return fail(&m->base, "m = %g: must be positive", s->m);
    if (!(s->k > 0.0)) return fail(&m->base, "k = %g: must be positive", s->k);
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

/* The Float64 variable `vr`, or NULL. */
static double *float64(State *s, fmi3ValueReference vr) {
    switch (vr) {
    case VR_TIME: return &s->time;
    case VR_X: return &s->x;
    case VR_V: return &s->v;
    case VR_F: return &s->force;
    case VR_M: return &s->m;
    case VR_K: return &s->k;
    case VR_X_A0: return &s->x_a0;
    case VR_V_A: return &s->v_a;
    case VR_X0: return &s->x0;
    case VR_V0: return &s->v0;
    default: return NULL;
    }
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3GetFloat64", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetFloat64", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        double *p = float64(&m->s, valueReferences[i]);
        if (p == NULL)
            return fail(&m->base, "fmi3GetFloat64: no Float64 variable has value reference %u", valueReferences[i]);
        values[i] = *p;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3SetFloat64", SETTABLE | STEP_MODE);
    ARRAYS("fmi3SetFloat64", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        fmi3ValueReference vr = valueReferences[i];
        double *p = float64(&m->s, vr);
        if (p == NULL || vr == VR_TIME || vr == VR_X || vr == VR_V)
            return fail(&m->base, "fmi3SetFloat64: no settable Float64 variable has value reference %u", vr);
        if (m->base.phase == STEP_MODE && vr != VR_F)
            return fail(&m->base, "fmi3SetFloat64: value reference %u is a parameter, fixed after initialization", vr);
        if (!isfinite(values[i]))
            return fail(&m->base, "fmi3SetFloat64: value reference %u set to %g", vr, values[i]);
        *p = values[i];
        if (vr == VR_F) m->s.stepped = 0;
        /* before stepping, the state is the initial one */
        if (vr == VR_X0) m->s.x = values[i];
        if (vr == VR_V0) m->s.v = values[i];
    }
    return fmi3OK;
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
NOT_OFFERED(fmi3GetInt32, const fmi3ValueReference vr[], size_t n, fmi3Int32 v[], size_t nv)
NOT_OFFERED(fmi3SetInt32, const fmi3ValueReference vr[], size_t n, const fmi3Int32 v[], size_t nv)
NOT_OFFERED(fmi3GetBoolean, const fmi3ValueReference vr[], size_t n, fmi3Boolean v[], size_t nv)
NOT_OFFERED(fmi3SetBoolean, const fmi3ValueReference vr[], size_t n, const fmi3Boolean v[], size_t nv)
NOT_OFFERED(fmi3GetString, const fmi3ValueReference vr[], size_t n, fmi3String v[], size_t nv)
NOT_OFFERED(fmi3SetString, const fmi3ValueReference vr[], size_t n, const fmi3String v[], size_t nv)
#pragma GCC diagnostic pop

EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h,
                             fmi3Boolean no_set_prior, fmi3Boolean *event_handling_needed,
                             fmi3Boolean *terminate, fmi3Boolean *early_return, fmi3Float64 *last_time) {
    (void)no_set_prior;
    ENTER("fmi3DoStep", STEP_MODE);
    if (event_handling_needed == NULL || terminate == NULL || early_return == NULL || last_time == NULL)
        return fail(&m->base, "fmi3DoStep: NULL out-pointer");
    State *s = &m->s;
    if (!(h > 0.0) || !isfinite(h)) return fail(&m->base, "fmi3DoStep: communicationStepSize = %g", h);
    if (fabs(t - s->time) > 1e-9 * fmax(1.0, fabs(t)))
        return fail(&m->base, "fmi3DoStep: currentCommunicationPoint = %.17g, but the FMU is at %.17g", t, s->time);
    double w = sqrt(s->k / s->m);
    double x_eq = s->x_a0 + s->v_a * t - s->force / s->k;
    double y = s->x - x_eq, dy = s->v - s->v_a;
    double c = cos(w * h), sn = sin(w * h);
    s->x = x_eq + s->v_a * h + y * c + dy / w * sn;
    s->v = s->v_a - y * w * sn + dy * c;
    s->time = t + h;
    s->last_h = h;
    s->stepped = 1;
    *event_handling_needed = false;
    *terminate = false;
    *early_return = false;
    *last_time = s->time;
    return fmi3OK;
}

/* d(output `unknown`)/dF over the last step (see the top of the file). */
static double sensitivity(const State *s, fmi3ValueReference unknown) {
    if (!s->stepped) return 0.0;
    double w = sqrt(s->k / s->m);
    return unknown == VR_X ? -(1.0 - cos(w * s->last_h)) / s->k : -sin(w * s->last_h) / (s->m * w);
}

EXPORT fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                               size_t n_unknowns, const fmi3ValueReference knowns[],
                                               size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
                                               fmi3Float64 sensitivities[], size_t n_sensitivities) {
    ENTER("fmi3GetDirectionalDerivative", INITIALIZATION | STEP_MODE);
    if ((n_unknowns > 0 && (unknowns == NULL || sensitivities == NULL)) ||
        (n_knowns > 0 && (knowns == NULL || seed == NULL)))
        return fail(&m->base, "fmi3GetDirectionalDerivative: NULL array");
    if (n_seed != n_knowns || n_sensitivities != n_unknowns)
        return fail(&m->base, "fmi3GetDirectionalDerivative: nSeed = %zu for %zu knowns, nSensitivity = %zu for %zu unknowns",
                    n_seed, n_knowns, n_sensitivities, n_unknowns);
    for (size_t j = 0; j < n_knowns; j++)
        if (knowns[j] != VR_F)
            return fail(&m->base, "fmi3GetDirectionalDerivative: known value reference %u is not the input F", knowns[j]);
    for (size_t i = 0; i < n_unknowns; i++) {
        if (unknowns[i] != VR_X && unknowns[i] != VR_V)
            return fail(&m->base, "fmi3GetDirectionalDerivative: unknown value reference %u is not an output", unknowns[i]);
        double d = 0.0;
        for (size_t j = 0; j < n_knowns; j++) d += sensitivity(&m->s, unknowns[i]) * seed[j];
        sensitivities[i] = d;
    }
    return fmi3OK;
}

/* ---- FMU state ------------------------------------------------------------ */

STATE_FUNCTIONS

#pragma GCC diagnostic ignored "-Wunused-parameter"
NOT_OFFERED(fmi3SerializedFMUStateSize, fmi3FMUState state, size_t *size)
NOT_OFFERED(fmi3SerializeFMUState, fmi3FMUState state, fmi3Byte bytes[], size_t size)
NOT_OFFERED(fmi3DeserializeFMUState, const fmi3Byte bytes[], size_t size, fmi3FMUState *state)
