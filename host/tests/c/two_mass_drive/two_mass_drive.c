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
 * with that input at 1 and the other at 0.
 *
 * All of that but the physics is ../common/linear_plant.h, shared with the
 * servo axis; this file gives the variables, the state at rest, the
 * derivatives and the outputs. */

#define MODEL_IDENTIFIER "TwoMassDrive"
#define GUID "{b323c20a-8726-4f8e-84df-75a94689c418}"
#define FASTEST_MODE "the belt's mode"

/* Value references (modelDescription.xml). */
enum {
    VR_U, VR_F,                                  /* inputs */
    VR_X_M, VR_X_L, VR_V, VR_A,                  /* outputs */
    VR_M_M, VR_M_L, VR_K_B, VR_C_B, VR_C_M,      /* Real parameters */
    VR_X0, VR_H_MAX,
    VR_V_M,                                      /* local state */
    VR_DER_X_M, VR_DER_V_M, VR_DER_X_L, VR_DER_V, /* state derivatives */
    N_REAL
};
#define FIRST_INPUT VR_U
#define LAST_INPUT VR_F
#define FIRST_OUTPUT VR_X_M
#define LAST_OUTPUT VR_A

#define FIRST_DERIVATIVE VR_DER_X_M

static const char *const REAL_NAMES[N_REAL] = {
    "u",   "F",   "x_m", "x_l", "v",  "a",     "m_m",      "m_l",      "k_b",      "c_b",
    "c_m", "x0",  "h_max", "v_m", "der(x_m)", "der(v_m)", "der(x_l)", "der(v)"};
static const double REAL_START[N_REAL] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5, 2.0, 2e4,
                                          20.0, 1.0, 0.0, 1e-4, 0.0, 0.0, 0.0, 0.0, 0.0};

/* The continuous state and the variable of each (the load's velocity is
 * the output v; the motor's, v_m, a local). */
enum { XM, VM, XL, VL, N_STATES };
static const unsigned int STATE_VR[N_STATES] = {VR_X_M, VR_V_M, VR_X_L, VR_V};

#include "../common/linear_plant.h"

static void rest(const double *p, double y[N_STATES]) {
    y[XM] = p[VR_X0];
    y[VM] = 0.0;
    y[XL] = p[VR_X0];
    y[VL] = 0.0;
}

/* dy/dt at y, the inputs u and F held. */
static void derivatives(const double *p, const double y[N_STATES], double dy[N_STATES]) {
    double belt = p[VR_K_B] * (y[XM] - y[XL]) + p[VR_C_B] * (y[VM] - y[VL]);
    dy[XM] = y[VM];
    dy[VM] = (p[VR_U] - belt - p[VR_C_M] * y[VM]) / p[VR_M_M];
    dy[XL] = y[VL];
    dy[VL] = (belt - p[VR_F]) / p[VR_M_L];
}

static double output(const double *p, const double y[N_STATES], const double dy[N_STATES], fmi2ValueReference vr) {
    (void)p;
    switch (vr) {
    case VR_X_M: return y[XM];
    case VR_X_L: return y[XL];
    case VR_V: return y[VL];
    default: return dy[VL]; /* VR_A */
    }
}

static int bad_parameter(const double *p) {
    if (!(p[VR_M_M] > 0)) return VR_M_M;
    if (!(p[VR_M_L] > 0)) return VR_M_L;
    if (!(p[VR_K_B] >= 0)) return VR_K_B;
    if (!(p[VR_C_B] >= 0)) return VR_C_B;
    if (!(p[VR_C_M] >= 0)) return VR_C_M;
    return -1;
}
