/* Gains: FMI 3.0 arrays, as a complete Co-Simulation FMU written by hand
 * in C for the tests of importers against the standard (FMI 3.0.1
 * §2.4.7.4, arrays; §2.2.6, getting and setting them), with its own
 * gains.xml beside this file. Three gated integrators with gains, and
 * what they feed:
 *
 *   k        Float64[3] parameter, the gains (start 1 2 3)
 *   enable   Boolean[3] parameter, which integrators run (true true false)
 *   A        Float64[2,3] parameter, a 2-D array of weights
 *   offset   Int32[2] parameter (10 20)
 *   u        Float64[3] input (0.5 -1 2)
 *   y        Float64[3] output, y[i]' = enable[i]·k[i]·u[i], integrated
 *            exactly for u held over the step (from 0)
 *   yd       Float64[3] output, yd[i] = k[i]·u[i]: direct feedthrough
 *   z        Float64[2,3] output, z[r,c] = A[r,c]·y[c]
 *   count    Int32[2] output, offset[i] + i·(the steps made), i = 1, 2
 *   positive Boolean[3] output, y[i] > 0
 *   total    Float64 output, a scalar among the arrays: the sum of yd
 *
 * The values of an array are read and written whole through its one
 * value reference, `nValues` counting elements (row-major for A and z);
 * a call whose nValues is not the number of elements its value
 * references take fails and says so, as does any array set in part.
 * Directional derivatives with u as the known (its three seeds) and any
 * of y, yd, z, total as unknowns: after a step, the step's sensitivity
 * (dy[i]/du[i] = enable[i]·k[i]·h); before a step, or once u is set
 * again, the direct feedthrough (none for y and z). FMU state got and
 * set. */

#define MODEL_IDENTIFIER "Gains"
#define INSTANTIATION_TOKEN "{9b1d3f5a-7c2e-4e6a-8b0d-2f4a6c8e0b1d}"
#include "fmi3_fmu.h"

enum {
    VR_TIME,
    VR_K,
    VR_U,
    VR_ENABLE,
    VR_A,
    VR_OFFSET,
    VR_Y,
    VR_YD,
    VR_Z,
    VR_COUNT,
    VR_POSITIVE,
    VR_TOTAL,
    N_VR
};

/* What an FMU state holds: everything but the base. */
typedef struct {
    double time, k[3], u[3], A[2][3], y[3];
    bool enable[3];
    int32_t offset[2], steps;
    double last_h; /* the last step's size */
    int stepped;   /* a step was made and u not set since */
} State;

typedef struct {
    Base base;
    State s;
} Model;

static void reset_values(Model *m) {
    m->s = (State){
        .k = {1.0, 2.0, 3.0},
        .u = {0.5, -1.0, 2.0},
        .A = {{1.0, 0.0, 0.5}, {0.0, 1.0, -1.0}},
        .enable = {true, true, false},
        .offset = {10, 20},
    };
}

COMMON_FUNCTIONS(reset_values)

/* The number of values of value reference `vr` (0: no such variable). */
static size_t size_of(fmi3ValueReference vr) {
    switch (vr) {
    case VR_TIME: case VR_TOTAL: return 1;
    case VR_K: case VR_U: case VR_ENABLE: case VR_Y: case VR_YD: case VR_POSITIVE: return 3;
    case VR_A: case VR_Z: return 6;
    case VR_OFFSET: case VR_COUNT: return 2;
    default: return 0;
    }
}

/* The values a call's value references take, or a failure: each must be
 * of the call's type (`is_type`), and nValues their number. */
static fmi3Status count_values(Model *m, const char *function, const fmi3ValueReference vrs[], size_t n,
                               const void *values, size_t n_values, int (*is_type)(fmi3ValueReference)) {
    if (n > 0 && (vrs == NULL || values == NULL)) return fail(&m->base, "%s: NULL array", function);
    size_t total = 0;
    for (size_t i = 0; i < n; i++) {
        if (vrs[i] >= N_VR || !is_type(vrs[i]))
            return fail(&m->base, "%s: value reference %u is not a variable of this type", function, vrs[i]);
        total += size_of(vrs[i]);
    }
    if (total != n_values)
        return fail(&m->base, "%s: nValues = %zu, but the value references take %zu values", function,
                    n_values, total);
    return fmi3OK;
}

static int is_float64(fmi3ValueReference vr) {
    return vr == VR_TIME || vr == VR_K || vr == VR_U || vr == VR_A || vr == VR_Y || vr == VR_YD ||
           vr == VR_Z || vr == VR_TOTAL;
}
static int is_int32(fmi3ValueReference vr) { return vr == VR_OFFSET || vr == VR_COUNT; }
static int is_boolean(fmi3ValueReference vr) { return vr == VR_ENABLE || vr == VR_POSITIVE; }

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
    for (int i = 0; i < 3; i++)
        if (!isfinite(m->s.k[i])) return fail(&m->base, "k[%d] = %g: must be finite", i + 1, m->s.k[i]);
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

/* Write the values of `vr` at `v` (Float64 ones). */
static double *put_float64(const State *s, fmi3ValueReference vr, double *v) {
    switch (vr) {
    case VR_TIME: *v++ = s->time; break;
    case VR_K: for (int i = 0; i < 3; i++) *v++ = s->k[i]; break;
    case VR_U: for (int i = 0; i < 3; i++) *v++ = s->u[i]; break;
    case VR_A: for (int r = 0; r < 2; r++) for (int c = 0; c < 3; c++) *v++ = s->A[r][c]; break;
    case VR_Y: for (int i = 0; i < 3; i++) *v++ = s->y[i]; break;
    case VR_YD: for (int i = 0; i < 3; i++) *v++ = s->k[i] * s->u[i]; break;
    case VR_Z: for (int r = 0; r < 2; r++) for (int c = 0; c < 3; c++) *v++ = s->A[r][c] * s->y[c]; break;
    case VR_TOTAL: {
        double total = 0.0;
        for (int i = 0; i < 3; i++) total += s->k[i] * s->u[i];
        *v++ = total;
        break;
    }
    }
    return v;
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3GetFloat64", GETTABLE | INSTANTIATED);
    fmi3Status status = count_values(m, "fmi3GetFloat64", valueReferences, nValueReferences, values,
                                     nValues, is_float64);
    if (status != fmi3OK) return status;
    double *v = values;
    for (size_t i = 0; i < nValueReferences; i++) v = put_float64(&m->s, valueReferences[i], v);
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3SetFloat64", SETTABLE | STEP_MODE);
    fmi3Status status = count_values(m, "fmi3SetFloat64", valueReferences, nValueReferences, values,
                                     nValues, is_float64);
    if (status != fmi3OK) return status;
    /* check everything before changing anything */
    const double *v = values;
    for (size_t i = 0; i < nValueReferences; i++) {
        fmi3ValueReference vr = valueReferences[i];
        if (vr != VR_K && vr != VR_U && vr != VR_A)
            return fail(&m->base, "fmi3SetFloat64: value reference %u cannot be set", vr);
        if (m->base.phase == STEP_MODE && vr != VR_U)
            return fail(&m->base, "fmi3SetFloat64: value reference %u is a parameter, fixed after initialization", vr);
        for (size_t j = 0; j < size_of(vr); j++, v++)
            if (!isfinite(*v)) return fail(&m->base, "fmi3SetFloat64: value reference %u set to %g", vr, *v);
    }
    v = values;
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_K: for (int j = 0; j < 3; j++) m->s.k[j] = *v++; break;
        case VR_U: for (int j = 0; j < 3; j++) m->s.u[j] = *v++; m->s.stepped = 0; break;
        case VR_A: for (int r = 0; r < 2; r++) for (int c = 0; c < 3; c++) m->s.A[r][c] = *v++; break;
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Int32 values[], size_t nValues) {
    ENTER("fmi3GetInt32", GETTABLE | INSTANTIATED);
    fmi3Status status = count_values(m, "fmi3GetInt32", valueReferences, nValueReferences, values,
                                     nValues, is_int32);
    if (status != fmi3OK) return status;
    int32_t *v = values;
    for (size_t i = 0; i < nValueReferences; i++)
        for (int j = 0; j < 2; j++)
            *v++ = valueReferences[i] == VR_OFFSET ? m->s.offset[j] : m->s.offset[j] + (j + 1) * m->s.steps;
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Int32 values[], size_t nValues) {
    ENTER("fmi3SetInt32", SETTABLE);
    fmi3Status status = count_values(m, "fmi3SetInt32", valueReferences, nValueReferences, values,
                                     nValues, is_int32);
    if (status != fmi3OK) return status;
    for (size_t i = 0; i < nValueReferences; i++)
        if (valueReferences[i] != VR_OFFSET)
            return fail(&m->base, "fmi3SetInt32: value reference %u cannot be set", valueReferences[i]);
    const int32_t *v = values;
    for (size_t i = 0; i < nValueReferences; i++)
        for (int j = 0; j < 2; j++) m->s.offset[j] = *v++;
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Boolean values[], size_t nValues) {
    ENTER("fmi3GetBoolean", GETTABLE | INSTANTIATED);
    fmi3Status status = count_values(m, "fmi3GetBoolean", valueReferences, nValueReferences, values,
                                     nValues, is_boolean);
    if (status != fmi3OK) return status;
    bool *v = values;
    for (size_t i = 0; i < nValueReferences; i++)
        for (int j = 0; j < 3; j++)
            *v++ = valueReferences[i] == VR_ENABLE ? m->s.enable[j] : m->s.y[j] > 0.0;
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Boolean values[], size_t nValues) {
    ENTER("fmi3SetBoolean", SETTABLE);
    fmi3Status status = count_values(m, "fmi3SetBoolean", valueReferences, nValueReferences, values,
                                     nValues, is_boolean);
    if (status != fmi3OK) return status;
    for (size_t i = 0; i < nValueReferences; i++)
        if (valueReferences[i] != VR_ENABLE)
            return fail(&m->base, "fmi3SetBoolean: value reference %u cannot be set", valueReferences[i]);
    const bool *v = values;
    for (size_t i = 0; i < nValueReferences; i++)
        for (int j = 0; j < 3; j++) m->s.enable[j] = *v++;
    return fmi3OK;
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
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
    for (int i = 0; i < 3; i++)
        if (s->enable[i]) s->y[i] += s->k[i] * s->u[i] * h;
    s->steps += 1;
    s->time = t + h;
    s->last_h = h;
    s->stepped = 1;
    *event_handling_needed = false;
    *terminate = false;
    *early_return = false;
    *last_time = s->time;
    return fmi3OK;
}

/* d(element i of y)/d(u[j]): the step's sensitivity after a step, else none. */
static double dy_du(const State *s, int i, int j) {
    return s->stepped && i == j && s->enable[i] ? s->k[i] * s->last_h : 0.0;
}

EXPORT fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                               size_t n_unknowns, const fmi3ValueReference knowns[],
                                               size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
                                               fmi3Float64 sensitivities[], size_t n_sensitivities) {
    ENTER("fmi3GetDirectionalDerivative", INITIALIZATION | STEP_MODE);
    if ((n_unknowns > 0 && (unknowns == NULL || sensitivities == NULL)) ||
        (n_knowns > 0 && (knowns == NULL || seed == NULL)))
        return fail(&m->base, "fmi3GetDirectionalDerivative: NULL array");
    size_t n_unknown_values = 0;
    for (size_t i = 0; i < n_unknowns; i++) {
        fmi3ValueReference vr = unknowns[i];
        if (vr != VR_Y && vr != VR_YD && vr != VR_Z && vr != VR_TOTAL)
            return fail(&m->base, "fmi3GetDirectionalDerivative: unknown value reference %u is not an output", vr);
        n_unknown_values += size_of(vr);
    }
    for (size_t j = 0; j < n_knowns; j++)
        if (knowns[j] != VR_U)
            return fail(&m->base, "fmi3GetDirectionalDerivative: known value reference %u is not the input u", knowns[j]);
    if (n_seed != 3 * n_knowns || n_sensitivities != n_unknown_values)
        return fail(&m->base,
                    "fmi3GetDirectionalDerivative: nSeed = %zu for %zu knowns of 3 values, nSensitivity = %zu for unknowns of %zu values",
                    n_seed, n_knowns, n_sensitivities, n_unknown_values);
    /* the seed of u: the sum over the knowns (u named more than once) */
    double du[3] = {0.0, 0.0, 0.0};
    for (size_t j = 0; j < n_knowns; j++)
        for (int c = 0; c < 3; c++) du[c] += seed[3 * j + c];
    const State *s = &m->s;
    double dy[3];
    for (int i = 0; i < 3; i++) dy[i] = dy_du(s, i, i) * du[i];
    double *out = sensitivities;
    for (size_t i = 0; i < n_unknowns; i++) {
        switch (unknowns[i]) {
        case VR_Y: for (int c = 0; c < 3; c++) *out++ = dy[c]; break;
        case VR_YD: for (int c = 0; c < 3; c++) *out++ = s->k[c] * du[c]; break;
        case VR_Z: for (int r = 0; r < 2; r++) for (int c = 0; c < 3; c++) *out++ = s->A[r][c] * dy[c]; break;
        case VR_TOTAL: {
            double d = 0.0;
            for (int c = 0; c < 3; c++) d += s->k[c] * du[c];
            *out++ = d;
            break;
        }
        }
    }
    return fmi3OK;
}

/* ---- FMU state ------------------------------------------------------------ */

STATE_FUNCTIONS

#pragma GCC diagnostic ignored "-Wunused-parameter"
NOT_OFFERED(fmi3SerializedFMUStateSize, fmi3FMUState state, size_t *size)
NOT_OFFERED(fmi3SerializeFMUState, fmi3FMUState state, fmi3Byte bytes[], size_t size)
NOT_OFFERED(fmi3DeserializeFMUState, const fmi3Byte bytes[], size_t size, fmi3FMUState *state)
