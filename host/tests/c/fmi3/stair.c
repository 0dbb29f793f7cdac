/* Stair: a counter that climbs one stair every second and asks to end the
 * simulation at the top, as a complete FMI 3.0 Co-Simulation FMU written
 * by hand in C (like the Modelica Reference FMU Stair; the FMI 2.0 one of
 * these tests is host/tests/c/stair), with its own stair.xml beside this
 * file.
 *
 *   counter   Int32 output, start 1, one more at every whole second
 *   even      Boolean output: counter is even
 *   height    Float64 output: counter * step_height
 *
 * When counter reaches `top` (10: at t = 9) the step that gets there
 * completes and fmi3DoStep sets terminateSimulation (FMI 3.0.1 §4.2.1):
 * the importer should end the run; a later fmi3DoStep is an error.
 *
 * For the tests of how an importer takes a broken step: with the
 * environment variable STAIR_EARLY_RETURN set, fmi3DoStep stops half way
 * through every step and says so (earlyReturn = true), although the
 * importer did not allow early return. */

#define MODEL_IDENTIFIER "Stair"
#define INSTANTIATION_TOKEN "{6a2e4c8f-1b3d-4f5a-9c7e-0d2b4f6a8c1e}"
#include "fmi3_fmu.h"

enum { VR_TIME, VR_COUNTER, VR_EVEN, VR_HEIGHT, VR_TOP, VR_STEP_HEIGHT };

typedef struct {
    Base base;
    double time, next_stair, step_height;
    int32_t counter, top;
    bool at_top;
} Model;

static void reset_values(Model *m) {
    m->time = 0.0;
    m->next_stair = 1.0;
    m->step_height = 1.0;
    m->counter = 1;
    m->top = 10;
    m->at_top = false;
}

COMMON_FUNCTIONS(reset_values)

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolerance_defined,
                                              fmi3Float64 tolerance, fmi3Float64 start,
                                              fmi3Boolean stop_defined, fmi3Float64 stop) {
    (void)tolerance_defined, (void)tolerance, (void)stop_defined, (void)stop;
    ENTER("fmi3EnterInitializationMode", INSTANTIATED);
    if (start != 0.0) return fail(&m->base, "fmi3EnterInitializationMode: Stair starts at t = 0, not %g", start);
    m->base.phase = INITIALIZATION;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ENTER("fmi3ExitInitializationMode", INITIALIZATION);
    if (m->top < 2) return fail(&m->base, "top = %d: must be at least 2", m->top);
    if (!(m->step_height >= 0.0)) return fail(&m->base, "step_height = %g: must be >= 0", m->step_height);
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
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_TIME: values[i] = m->time; break;
        case VR_HEIGHT: values[i] = m->counter * m->step_height; break;
        case VR_STEP_HEIGHT: values[i] = m->step_height; break;
        default: return fail(&m->base, "fmi3GetFloat64: no Float64 variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3SetFloat64", SETTABLE);
    ARRAYS("fmi3SetFloat64", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] != VR_STEP_HEIGHT || !isfinite(values[i]))
            return fail(&m->base, "fmi3SetFloat64: value reference %u set to %g", valueReferences[i], values[i]);
        m->step_height = values[i];
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Int32 values[], size_t nValues) {
    ENTER("fmi3GetInt32", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetInt32", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_COUNTER: values[i] = m->counter; break;
        case VR_TOP: values[i] = m->top; break;
        default: return fail(&m->base, "fmi3GetInt32: no Int32 variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Int32 values[], size_t nValues) {
    ENTER("fmi3SetInt32", SETTABLE);
    ARRAYS("fmi3SetInt32", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_COUNTER: m->counter = values[i]; break;
        case VR_TOP: m->top = values[i]; break;
        default: return fail(&m->base, "fmi3SetInt32: no settable Int32 variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Boolean values[], size_t nValues) {
    ENTER("fmi3GetBoolean", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetBoolean", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] != VR_EVEN)
            return fail(&m->base, "fmi3GetBoolean: no Boolean variable has value reference %u", valueReferences[i]);
        values[i] = m->counter % 2 == 0;
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
    if (nValueReferences > 0)
        return fail(&m->base, "fmi3GetString: no String variable has value reference %u", valueReferences[0]);
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3String values[], size_t nValues) {
    ENTER("fmi3SetString", SETTABLE);
    ARRAYS("fmi3SetString", values);
    if (nValueReferences > 0)
        return fail(&m->base, "fmi3SetString: no String variable has value reference %u", valueReferences[0]);
    return fmi3OK;
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 dt,
                             fmi3Boolean no_set_prior, fmi3Boolean *event_handling_needed,
                             fmi3Boolean *terminate, fmi3Boolean *early_return, fmi3Float64 *last_time) {
    (void)no_set_prior;
    ENTER("fmi3DoStep", STEP_MODE);
    if (event_handling_needed == NULL || terminate == NULL || early_return == NULL || last_time == NULL)
        return fail(&m->base, "fmi3DoStep: NULL out-pointer");
    if (m->at_top) return fail(&m->base, "fmi3DoStep: the simulation has ended at the top (t = %g)", m->time);
    if (!(dt > 0.0) || !isfinite(dt)) return fail(&m->base, "fmi3DoStep: communicationStepSize = %g", dt);
    if (fabs(t - m->time) > 1e-9 * fmax(1.0, fabs(t)))
        return fail(&m->base, "fmi3DoStep: currentCommunicationPoint = %.17g, but the FMU is at %.17g", t, m->time);
    double end = getenv("STAIR_EARLY_RETURN") != NULL ? t + dt / 2 : t + dt;
    while (m->next_stair <= end + 1e-9 * fmax(1.0, end) && m->counter < m->top) {
        m->counter += 1;
        m->next_stair += 1.0;
    }
    m->time = end;
    m->at_top = m->counter >= m->top;
    *event_handling_needed = false;
    *terminate = m->at_top;
    *early_return = end < t + dt;
    *last_time = end;
    return fmi3OK;
}

#pragma GCC diagnostic ignored "-Wunused-parameter"
NOT_OFFERED(fmi3GetFMUState, fmi3FMUState *state)
NOT_OFFERED(fmi3SetFMUState, fmi3FMUState state)
NOT_OFFERED(fmi3FreeFMUState, fmi3FMUState *state)
NOT_OFFERED(fmi3SerializedFMUStateSize, fmi3FMUState state, size_t *size)
NOT_OFFERED(fmi3SerializeFMUState, fmi3FMUState state, fmi3Byte bytes[], size_t size)
NOT_OFFERED(fmi3DeserializeFMUState, const fmi3Byte bytes[], size_t size, fmi3FMUState *state)
NOT_OFFERED(fmi3GetDirectionalDerivative, const fmi3ValueReference u[], size_t nu,
            const fmi3ValueReference k[], size_t nk, const fmi3Float64 seed[], size_t ns,
            fmi3Float64 s[], size_t nsens)
