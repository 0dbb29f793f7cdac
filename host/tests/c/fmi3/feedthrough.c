/* Feedthrough: one input of each FMI 3.0 variable type fed through to an
 * output of the same type, as a complete Co-Simulation FMU written by
 * hand in C for the tests of importers against the standard (like the
 * Modelica Reference FMU Feedthrough), with its own feedthrough.xml
 * beside this file: Float32, Float64, Int8, UInt8, Int16, UInt16, Int32,
 * UInt32, Int64, UInt64, Boolean and Enumeration (which FMI 3.0 reads and
 * writes as Int64), each `<Type>_input` → `<Type>_output`, read and
 * written through the getter and setter of its type (fmi3GetUInt8, …),
 * and a Float32 array of two. Binary and Clock are not here: an importer
 * that refuses them by name cannot import an FMU that has them.
 *
 * For the tests of what an importer does with a value it cannot hold:
 * with the environment variable FEEDTHROUGH_ODD_UINT64 set, UInt64_output
 * is UInt64_input + 1 (2^53 + 1 from the start value, which no 64-bit
 * float holds). */

#define MODEL_IDENTIFIER "Feedthrough"
#define INSTANTIATION_TOKEN "{2e4a6c8e-0b1d-4f3a-9c5e-7a9b1d3f5e7c}"
#define OFFERS_EVERY_TYPE
#include "fmi3_fmu.h"

enum {
    VR_TIME,
    VR_FLOAT32_IN, VR_FLOAT32_OUT,
    VR_FLOAT64_IN, VR_FLOAT64_OUT,
    VR_INT8_IN, VR_INT8_OUT,
    VR_UINT8_IN, VR_UINT8_OUT,
    VR_INT16_IN, VR_INT16_OUT,
    VR_UINT16_IN, VR_UINT16_OUT,
    VR_INT32_IN, VR_INT32_OUT,
    VR_UINT32_IN, VR_UINT32_OUT,
    VR_INT64_IN, VR_INT64_OUT,
    VR_UINT64_IN, VR_UINT64_OUT,
    VR_BOOLEAN_IN, VR_BOOLEAN_OUT,
    VR_ENUMERATION_IN, VR_ENUMERATION_OUT,
    VR_FLOAT32_ARRAY_IN, VR_FLOAT32_ARRAY_OUT
};

typedef struct {
    Base base;
    double time;
    float float32, float32_array[2];
    double float64;
    int8_t int8;
    uint8_t uint8;
    int16_t int16;
    uint16_t uint16;
    int32_t int32;
    uint32_t uint32;
    int64_t int64, enumeration;
    uint64_t uint64;
    bool boolean;
} Model;

/* The start values of feedthrough.xml: each type's extremes where a
 * 64-bit float holds them. */
static void reset_values(Model *m) {
    m->time = 0.0;
    m->float32 = 0.1f;
    m->float32_array[0] = 1.5f;
    m->float32_array[1] = -2.25f;
    m->float64 = 0.1;
    m->int8 = INT8_MIN;
    m->uint8 = UINT8_MAX;
    m->int16 = INT16_MIN;
    m->uint16 = UINT16_MAX;
    m->int32 = INT32_MIN;
    m->uint32 = UINT32_MAX;
    m->int64 = -9007199254740992LL; /* -2^53 */
    m->uint64 = 9007199254740992ULL; /* 2^53 */
    m->boolean = true;
    m->enumeration = 2;
}

COMMON_FUNCTIONS(reset_values)

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolerance_defined,
                                              fmi3Float64 tolerance, fmi3Float64 start,
                                              fmi3Boolean stop_defined, fmi3Float64 stop) {
    (void)tolerance_defined, (void)tolerance, (void)stop_defined, (void)stop;
    ENTER("fmi3EnterInitializationMode", INSTANTIATED);
    m->time = start;
    m->base.phase = INITIALIZATION;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ENTER("fmi3ExitInitializationMode", INITIALIZATION);
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

/* fmi3Get<Type> and fmi3Set<Type> of a type with one input, `field`, and
 * its output, `output` (an expression of the model `m`). */
#define SCALAR_FUNCTIONS(Type, field, VR_IN, VR_OUT, output)                                        \
    EXPORT fmi3Status fmi3Get##Type(fmi3Instance instance, const fmi3ValueReference valueReferences[], \
                                    size_t nValueReferences, fmi3##Type values[], size_t nValues) {   \
        ENTER("fmi3Get" #Type, GETTABLE | INSTANTIATED);                                           \
        ARRAYS("fmi3Get" #Type, values);                                                           \
        for (size_t i = 0; i < nValueReferences; i++) {                                            \
            if (valueReferences[i] == VR_IN) values[i] = m->field;                                 \
            else if (valueReferences[i] == VR_OUT) values[i] = output;                             \
            else return fail(&m->base, "fmi3Get" #Type ": no " #Type " variable has value reference %u", \
                             valueReferences[i]);                                                  \
        }                                                                                          \
        return fmi3OK;                                                                             \
    }                                                                                              \
    EXPORT fmi3Status fmi3Set##Type(fmi3Instance instance, const fmi3ValueReference valueReferences[], \
                                    size_t nValueReferences, const fmi3##Type values[], size_t nValues) { \
        ENTER("fmi3Set" #Type, SETTABLE | STEP_MODE);                                              \
        ARRAYS("fmi3Set" #Type, values);                                                           \
        for (size_t i = 0; i < nValueReferences; i++)                                              \
            if (valueReferences[i] != VR_IN)                                                       \
                return fail(&m->base, "fmi3Set" #Type ": no settable " #Type " variable has value reference %u", \
                            valueReferences[i]);                                                   \
        for (size_t i = 0; i < nValueReferences; i++) m->field = values[i];                        \
        return fmi3OK;                                                                             \
    }

SCALAR_FUNCTIONS(Int8, int8, VR_INT8_IN, VR_INT8_OUT, m->int8)
SCALAR_FUNCTIONS(UInt8, uint8, VR_UINT8_IN, VR_UINT8_OUT, m->uint8)
SCALAR_FUNCTIONS(Int16, int16, VR_INT16_IN, VR_INT16_OUT, m->int16)
SCALAR_FUNCTIONS(UInt16, uint16, VR_UINT16_IN, VR_UINT16_OUT, m->uint16)
SCALAR_FUNCTIONS(Int32, int32, VR_INT32_IN, VR_INT32_OUT, m->int32)
SCALAR_FUNCTIONS(UInt32, uint32, VR_UINT32_IN, VR_UINT32_OUT, m->uint32)
SCALAR_FUNCTIONS(UInt64, uint64, VR_UINT64_IN, VR_UINT64_OUT,
                 m->uint64 + (getenv("FEEDTHROUGH_ODD_UINT64") != NULL))
SCALAR_FUNCTIONS(Boolean, boolean, VR_BOOLEAN_IN, VR_BOOLEAN_OUT, m->boolean)

/* Float64: the scalars, and the time */
EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3GetFloat64", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetFloat64", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_TIME: values[i] = m->time; break;
        case VR_FLOAT64_IN: case VR_FLOAT64_OUT: values[i] = m->float64; break;
        default: return fail(&m->base, "fmi3GetFloat64: no Float64 variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    ENTER("fmi3SetFloat64", SETTABLE | STEP_MODE);
    ARRAYS("fmi3SetFloat64", values);
    for (size_t i = 0; i < nValueReferences; i++)
        if (valueReferences[i] != VR_FLOAT64_IN)
            return fail(&m->base, "fmi3SetFloat64: no settable Float64 variable has value reference %u", valueReferences[i]);
    for (size_t i = 0; i < nValueReferences; i++) m->float64 = values[i];
    return fmi3OK;
}

/* Float32: a scalar and an array of two, nValues counting the elements */
EXPORT fmi3Status fmi3GetFloat32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, fmi3Float32 values[], size_t nValues) {
    ENTER("fmi3GetFloat32", GETTABLE | INSTANTIATED);
    size_t k = 0;
    for (size_t i = 0; i < nValueReferences; i++) {
        fmi3ValueReference vr = valueReferences[i];
        size_t n = vr == VR_FLOAT32_ARRAY_IN || vr == VR_FLOAT32_ARRAY_OUT ? 2 : 1;
        if (k + n > nValues) return fail(&m->base, "fmi3GetFloat32: nValues = %zu is too small", nValues);
        if (vr == VR_FLOAT32_IN || vr == VR_FLOAT32_OUT) values[k] = m->float32;
        else if (n == 2) values[k] = m->float32_array[0], values[k + 1] = m->float32_array[1];
        else return fail(&m->base, "fmi3GetFloat32: no Float32 variable has value reference %u", vr);
        k += n;
    }
    if (k != nValues) return fail(&m->base, "fmi3GetFloat32: nValues = %zu for %zu values", nValues, k);
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                 size_t nValueReferences, const fmi3Float32 values[], size_t nValues) {
    ENTER("fmi3SetFloat32", SETTABLE | STEP_MODE);
    size_t k = 0;
    for (size_t i = 0; i < nValueReferences; i++) {
        fmi3ValueReference vr = valueReferences[i];
        size_t n = vr == VR_FLOAT32_ARRAY_IN ? 2 : 1;
        if (vr != VR_FLOAT32_IN && vr != VR_FLOAT32_ARRAY_IN)
            return fail(&m->base, "fmi3SetFloat32: no settable Float32 variable has value reference %u", vr);
        if (k + n > nValues) return fail(&m->base, "fmi3SetFloat32: nValues = %zu is too small", nValues);
        if (n == 1) m->float32 = values[k];
        else m->float32_array[0] = values[k], m->float32_array[1] = values[k + 1];
        k += n;
    }
    if (k != nValues) return fail(&m->base, "fmi3SetFloat32: nValues = %zu for %zu values", nValues, k);
    return fmi3OK;
}

/* Int64: the Int64 and the Enumeration variables */
EXPORT fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Int64 values[], size_t nValues) {
    ENTER("fmi3GetInt64", GETTABLE | INSTANTIATED);
    ARRAYS("fmi3GetInt64", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        switch (valueReferences[i]) {
        case VR_INT64_IN: case VR_INT64_OUT: values[i] = m->int64; break;
        case VR_ENUMERATION_IN: case VR_ENUMERATION_OUT: values[i] = m->enumeration; break;
        default: return fail(&m->base, "fmi3GetInt64: no Int64 or Enumeration variable has value reference %u", valueReferences[i]);
        }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Int64 values[], size_t nValues) {
    ENTER("fmi3SetInt64", SETTABLE | STEP_MODE);
    ARRAYS("fmi3SetInt64", values);
    for (size_t i = 0; i < nValueReferences; i++) {
        fmi3ValueReference vr = valueReferences[i];
        if (vr != VR_INT64_IN && vr != VR_ENUMERATION_IN)
            return fail(&m->base, "fmi3SetInt64: no settable Int64 or Enumeration variable has value reference %u", vr);
        if (vr == VR_ENUMERATION_IN && (values[i] < 1 || values[i] > 3))
            return fail(&m->base, "fmi3SetInt64: Enumeration_input = %lld is not an item of Option (1..3)", (long long)values[i]);
    }
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] == VR_INT64_IN) m->int64 = values[i];
        else m->enumeration = values[i];
    }
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
    if (!(h > 0.0) || !isfinite(h)) return fail(&m->base, "fmi3DoStep: communicationStepSize = %g", h);
    m->time = t + h;
    *event_handling_needed = false;
    *terminate = false;
    *early_return = false;
    *last_time = m->time;
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
