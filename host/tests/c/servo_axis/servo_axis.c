/* ServoAxis: a position-controlled linear axis, a motor driving a carriage
 * through a belt (or gear) spring, friction on the carriage, with a PD
 * position controller on the motor's encoder. A complete FMI 2.0
 * Co-Simulation FMU written by hand in plain C, with its own hand-written
 * modelDescription.xml beside this file; not made by this project's
 * exporter. A second plant that is not Rig1D, unlike TwoMassDrive in
 * structure: driven by a position reference, not a force, so the friction
 * shows in the tracking error and in the controller's force as well as in
 * the positions.
 *
 *   u         = Kp (r - x_m) - Kd x_m'                         (PD on the motor)
 *   m_m x_m'' = u - k_g (x_m - x_l) - c_g (x_m' - x_l') - c_m x_m'
 *   m_l x_l'' = k_g (x_m - x_l) + c_g (x_m' - x_l') - F
 *
 *   r          position reference of the motor (input, m)
 *   F          friction force on the carriage, resisting positive carriage
 *              velocity (input, N)
 *   x_m, x_l   motor and carriage positions (outputs, m; the motor's as its
 *              encoder reads it, in the carriage's linear units)
 *   v = x_l'   carriage velocity: the slip velocity of a friction FMU (output)
 *   a = x_l''  carriage acceleration (output; direct feedthrough of F only)
 *   u          the controller's force on the motor, as a drive's current
 *              measures it (output; direct feedthrough of r only)
 *
 * m_m is the motor's equivalent mass (rotor inertia / radius^2), c_m its
 * viscous friction; the controller has no integral term, so a carriage
 * held by friction sits off the reference by about F / Kp.
 *
 * Both masses start at rest at x0, the spring relaxed. canInterpolateInputs:
 * an input given a slope (fmi2SetRealInputDerivatives, order 1) ramps over
 * the next step, as a drive's interpolator feeds its position loop a
 * reference between set-points (held over a 1 ms step, a reference moving
 * at 0.1 m/s lags 50 µm, Kp times that in u); without one it is held. Each
 * step is integrated by RK4 in ceil(h / h_max) equal sub-steps; RK4 is unstable once h_max exceeds about
 * 2.8 / sqrt(k_g (1/m_m + 1/m_l)) (the belt's mode) or 2.8 m_m / Kd (the
 * controller's damping on the motor). The plant with its controller is
 * linear in (state, r, F), so the directional derivatives right after a
 * step are that step's exact sensitivity to r and F, and otherwise the
 * direct feedthrough (du/dr = Kp, da/dF = -1/m_l). The FMI machinery (state
 * machine, checks, logging, FMUstate, RK4, sensitivities) is
 * ../common/linear_plant.h, shared with TwoMassDrive. */

#define MODEL_IDENTIFIER "ServoAxis"
#define GUID "{6a2aca2e-6fb0-49ea-b489-26671e0dceff}"
#define FASTEST_MODE "the belt's mode or the controller's damping Kd/m_m"
#define INTERPOLATES_INPUTS 1

/* Value references (modelDescription.xml). */
enum {
    VR_R, VR_F,                                  /* inputs */
    VR_X_M, VR_X_L, VR_V, VR_A, VR_U,            /* outputs */
    VR_M_M, VR_M_L, VR_K_G, VR_C_G, VR_C_M,      /* Real parameters */
    VR_KP, VR_KD, VR_X0, VR_H_MAX,
    VR_V_M,                                      /* local state */
    VR_DER_X_M, VR_DER_V_M, VR_DER_X_L, VR_DER_V, /* state derivatives */
    N_REAL
};
#define FIRST_INPUT VR_R
#define LAST_INPUT VR_F
#define FIRST_OUTPUT VR_X_M
#define LAST_OUTPUT VR_U

#define FIRST_DERIVATIVE VR_DER_X_M

static const char *const REAL_NAMES[N_REAL] = {
    "r",  "F",  "x_m", "x_l", "v",     "a",   "u",        "m_m",      "m_l",      "k_g",   "c_g",
    "c_m", "Kp", "Kd", "x0",  "h_max", "v_m", "der(x_m)", "der(v_m)", "der(x_l)", "der(v)"};
static const double REAL_START[N_REAL] = {0.0, 0.0, 0.0,    0.0,   0.0, 0.0,  0.0,
                                          0.5, 2.0, 2e4,    20.0,  1.0, 4000.0, 140.0,
                                          0.0, 1e-4, 0.0,   0.0,   0.0, 0.0,  0.0};

/* The continuous state and the variable of each (the carriage's velocity
 * is the output v; the motor's, v_m, a local). */
enum { XM, VM, XL, VL, N_STATES };
static const unsigned int STATE_VR[N_STATES] = {VR_X_M, VR_V_M, VR_X_L, VR_V};

#include "../common/linear_plant.h"

static void rest(const double *p, double y[N_STATES]) {
    y[XM] = p[VR_X0];
    y[VM] = 0.0;
    y[XL] = p[VR_X0];
    y[VL] = 0.0;
}

/* The PD controller's force at y, the reference r held. */
static double control(const double *p, const double y[N_STATES]) {
    return p[VR_KP] * (p[VR_R] - y[XM]) - p[VR_KD] * y[VM];
}

/* dy/dt at y, the inputs r and F held. */
static void derivatives(const double *p, const double y[N_STATES], double dy[N_STATES]) {
    double belt = p[VR_K_G] * (y[XM] - y[XL]) + p[VR_C_G] * (y[VM] - y[VL]);
    dy[XM] = y[VM];
    dy[VM] = (control(p, y) - belt - p[VR_C_M] * y[VM]) / p[VR_M_M];
    dy[XL] = y[VL];
    dy[VL] = (belt - p[VR_F]) / p[VR_M_L];
}

static double output(const double *p, const double y[N_STATES], const double dy[N_STATES], fmi2ValueReference vr) {
    switch (vr) {
    case VR_X_M: return y[XM];
    case VR_X_L: return y[XL];
    case VR_V: return y[VL];
    case VR_A: return dy[VL];
    default: return control(p, y); /* VR_U */
    }
}

static int bad_parameter(const double *p) {
    if (!(p[VR_M_M] > 0)) return VR_M_M;
    if (!(p[VR_M_L] > 0)) return VR_M_L;
    if (!(p[VR_K_G] >= 0)) return VR_K_G;
    if (!(p[VR_C_G] >= 0)) return VR_C_G;
    if (!(p[VR_C_M] >= 0)) return VR_C_M;
    if (!(p[VR_KP] >= 0)) return VR_KP;
    if (!(p[VR_KD] >= 0)) return VR_KD;
    return -1;
}
