/*
 * An independent simulator of the hidden-effect datasets of `fricsim
 * diagnose`: a mass pulled through a spring by a measured actuator
 * position, with LuGre friction plus at most one hidden effect. It shares
 * no code with the FMUs it checks (plain C, its own integrator), so data it
 * makes test the diagnosis the way a user's measurements would.
 *
 *   m·x'' = k·(x_a(t) − x) − c·x' − F
 *   F     = σ0·z + σ1·z' + σ2·v,        z' = v − σ0·|v|·z / g(v, x)
 *   g     = s(x)·[Fc_dir + (Fs_dir − Fc_dir)·exp(−(v/vs)²)]
 *
 * (Canudas de Wit, Olsson, Åström and Lischinsky 1995, with the direction-
 * and position-dependent levels of Sun et al. 2016), where Fc_dir, Fs_dir
 * are Fc, Fs for v ≥ 0 and Fc_neg, Fs_neg for v < 0, and s(x) is
 * piecewise linear through (x_table[i], scale[i]) and constant beyond.
 *
 * Integration: classical Runge–Kutta, each step a fraction (step_fraction,
 * 0.5) of the contact's stiffest time scale at the current state:
 * min(√(m/σ0), m/σ1, g/(σ0·|v|)), at most h_max (1e-5 s), landing on every
 * sample time. Halving the fraction moves the samples by far less than the 1 µm
 * encoder step (checked by tests/test_diagnose_independent.py and, for
 * law=gms, tests/test_independent_gms.py; law=elastoplastic,
 * tests/test_independent_elastoplastic.py). Sampling: every `sample`
 * seconds; the mass and the actuator are read through an encoder (Gaussian
 * noise of `noise` m, then rounded to `resolution` m).
 *
 * dither_amp, dither_period: a small oscillation added to the actuator's
 * position, x_a(t) + dither_amp·sin(2π·t/dither_period) (none by default:
 * the drives are then computed exactly as without the keys).
 *
 * law=gms: instead of LuGre, the Generalized Maxwell-Slip law (Al-Bender,
 * Lampaert and Swevers, "The generalized Maxwell-slip model: a novel model
 * for friction simulation and compensation", IEEE TAC 50(11), 2005):
 * n_elements elasto-slide elements in parallel, element i of stiffness
 * k_i and weight α_i (Σ α_i = 1), its state its force F_i and its mode,
 * sticking or slipping in a direction. With s(v) = g(v, x) above (the
 * Stribeck curve Fc + (Fs − Fc)·exp(−(v/vs)²), its levels by direction
 * and position as for LuGre):
 *
 *   sticking:  dF_i/dt = k_i·v,  until sgn(v)·F_i reaches α_i·s(v); then
 *              it slips in the direction of v;
 *   slipping:  dF_i/dt = C·(sgn(v)·α_i − F_i/s(v))  (the attraction C, N/s),
 *              until v changes sign (or stops): then it sticks, keeping
 *              its force;
 *   F = Σ F_i + σ_i·dζ_i/dt terms + σ2·v
 *     = Σ F_i + (σ1/σ0)·Σ dF_i/dt + σ2·v,
 *
 * the paper's micro-damping σ_i·dζ_i/dt of each element's deformation
 * ζ_i = F_i/k_i taken as σ_i = σ1·k_i/σ0, so that a contact at rest is
 * damped by σ1 as LuGre's is (sigma1=0: none, F = Σ F_i + σ2·v). The
 * elements are built from LuGre's parameters, so that "GMS with LuGre's
 * levels and presliding stiffness σ0" is one law: N = n_elements
 * elements of equal stiffness k_i = σ0/N, slip distances
 *
 *   Δ_i = −(Fc/σ0)·ln(1 − (i − 1/2)/N),   i = 1..N
 *
 * (the midpoint quantiles of an exponential of mean Fc/σ0) and weights
 * α_i = k_i·Δ_i / Σ_j k_j·Δ_j, so that the virgin curve at slow speed,
 * F_v(x) = Σ_i min(k_i·x, α_i·Fs), starts with stiffness σ0 and loses it
 * like LuGre's σ0·exp(−σ0·x/Fc), and every element slipping gives s(v).
 * Slow reversals then follow Masing's rule, F = F_r − 2·F_v((x_r − x)/2)
 * after a reversal at (x_r, F_r), and a closed minor loop is wiped out
 * (the nonlocal memory of presliding hysteresis). Integration: the modes
 * are held over each Runge–Kutta step (a slipping element's sgn(v) is its
 * direction); a switch inside a step is located by linear interpolation
 * and the step taken again to end just past it (within 0.5 % of the
 * step); after each step a sticking element at or past its level is set
 * to it and slips, and a slipping element whose v has changed sign (or is
 * 0) sticks. The step is besides at most step_fraction·s/C (the slipping
 * elements' relaxation time) and, while moving, 0.1·step_fraction·
 * min(α_i·s/k_i)/|v| over the sticking elements (each travels at most 5 %
 * of its slip distance in a step at the default fraction). C: `C`
 * (default 1000 N/s).
 *
 * law=elastoplastic: instead of LuGre, the single-state elasto-plastic
 * law (Dupont, Hayward, Armstrong and Altpeter, "Single state
 * elastoplastic friction models", IEEE TAC 47(5), 2002): LuGre whose
 * bristle deflection is purely elastic below the break-away deflection
 * z_ba, so that a force below break-away makes no drift:
 *
 *   z' = v − α(z, v)·σ0·|v|·z / g(v),   F = σ0·z + σ1·z' + σ2·v,
 *
 * g(v) = Fc + (Fs − Fc)·exp(−(v/vs)²) the Stribeck curve above, and with
 * w = sgn(v)·z and w_ss = g(v)/σ0 (the steady deflection):
 *
 *   α = 0                                            if w ≤ z_ba,
 *   α = ½·sin(π·(w − (w_ss + z_ba)/2)/(w_ss − z_ba)) + ½   if z_ba < w < w_ss,
 *   α = 1                                            if w ≥ w_ss,
 *
 * 0 ≤ z_ba < min(Fc, Fs)/σ0 (key `z_ba`, m). So unloading (sgn v ≠ sgn z)
 * is elastic, z' = v, and so is loading up to z_ba; past w_ss the law is
 * LuGre's. α is continuous with its slope in w (the sine meets 0 and 1
 * with zero slope), so Runge–Kutta needs no event location at z_ba and
 * w_ss; its step is besides at most step_fraction·(2/π)·(w_ss − z_ba)/|v|,
 * the time scale of the sine's steepest part (the bound of ∂z'/∂z there),
 * so that the transition is resolved. The levels are one pair for both
 * directions and no position table (refused with the law).
 *
 * plant=prescribed: no dynamics, the body's position prescribed, for
 * checking a law alone: x(t) = amp·sin(2π·t/period), or with
 * `path=x0,x1,...` the turning points x0 → x1 → ... traversed at constant
 * speed (`speed`, m/s: one value, or one per segment), at rest at the
 * last; the steps land on the turning points. Output: time,true_x,true_F
 * every sample (truth, noise and resolution do not apply).
 *
 * plant=two_mass: instead, a motor driving a load through a belt spring,
 * the friction on the load (a plant that is not Rig1D):
 *
 *   m_m·x_m'' = u(t) − k·(x_m − x) − c·(x_m' − x') − c_m·x_m'
 *   m·x''     = k·(x_m − x) + c·(x_m' − x') − F
 *
 * driven by a measured motor force u(t) = amp·[(1 − a2)·cos(ω1·t) +
 * a2·cos(ω2·t)] (the load's mean speed stays zero), both positions read
 * through the encoder. Output: time,drive.u,drive.x_m,drive.x_l[,...].
 *
 * plant=servo: the same drive train (k, c the belt's stiffness and
 * damping) under a PD position controller on the motor, which tracks the
 * reference r(t) of `drive` (the actuator motion above: sines, a rounded
 * triangle or ramped steps, the mass's speed crossing zero):
 *
 *   u         = Kp·(r(t) − x_m) − Kd·x_m'
 *   m_m·x_m'' = u − k·(x_m − x) − c·(x_m' − x') − c_m·x_m'
 *   m·x''     = k·(x_m − x) + c·(x_m' − x') − F
 *
 * both masses at rest at r(0) to start. The controller reads the true motor
 * position and velocity (a continuous-time controller, as the nominal
 * model has it); r is written as computed, the controller's force u as a
 * drive's current measurement reads it (rounded to force_resolution N, 0:
 * exact), the two positions through the encoder. Output:
 * time,drive.r,drive.x_m,drive.x_l,drive.u[,true_x,true_F] (true_x: the
 * carriage's noise-free position, as for every plant).
 *
 * drive=hold: the actuator through given positions hold_x = p_0..p_n at
 * times hold_t = t_0..t_n (s, increasing; the lists from the caller, e.g.
 * cases.py's presliding_drift, which sets them so that the spring force
 * holds chosen levels): from t_i to t_(i+1) it moves from p_i to
 * p_(i+1) as p_i + (p_(i+1) − p_i)·(u − sin(2πu)/(2π)), u the fraction of
 * the interval (speed and acceleration zero at both ends), at rest at p_0
 * before t_0 and at p_n after t_n. The dither (dither_amp,
 * dither_period) is on only in the intervals whose flag in hold_dither (one
 * 0 or 1 per interval) is 1, from the interval's start,
 * dither_amp·e(τ)·sin(2π·τ/dither_period) with τ the time since it, faded
 * in over the first dither period and out over the last by e =
 * ½·(1 − cos(π·τ/dither_period)) (on an interval of a whole number of
 * dither periods, two or more, the actuator is then twice continuously
 * differentiable throughout).
 *
 * Usage: lugre_rig key=value ... > data.csv
 *   keys: m c k Fc Fs Fc_neg Fs_neg vs sigma0 sigma1 sigma2 duration
 *         sample resolution noise seed drive (sines|triangle|steps|hold)
 *         amp period  n_table x_table scale (comma lists)
 *         plant (rig|two_mass|servo|prescribed)  m_m c_m (two_mass,
 *         servo)  Kp Kd  force_resolution (servo)  path speed (comma
 *         lists; prescribed)  dither_amp dither_period
 *         hold_t hold_x hold_dither (comma lists; hold)
 *         law (lugre|gms|elastoplastic)  n_elements C (gms)
 *         z_ba (elastoplastic)  step_fraction h_max
 *         truth=1 (also write the noise-free x and the friction force)
 * Output: time,rig.x_act_in,rig.x[,true_x,true_F]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_TABLE 16

static double m = 1, c = 0, k = 1000, Fc = 2, Fs = 2, Fc_neg = -1, Fs_neg = -1;
static double vs = 0.01, sigma0 = 1e6, sigma1 = 1e3, sigma2 = 0;
static double duration = 40, sample = 1e-3, resolution = 1e-6, noise = 0;
static double amp = 0.05, period = 4;
static uint64_t seed = 1;
static char drive[32] = "sines";
static int n_table = 0;
static double x_table[MAX_TABLE], scale_tab[MAX_TABLE];
static int write_truth = 0;
static int two_mass = 0, servo = 0; /* plant=two_mass, plant=servo */
static double m_m = 0.5, c_m = 1.0;
static double Kp = 4000, Kd = 140, force_resolution = 0;
static double step_fraction = 0.5; /* of the stiffest time scale */
static double h_max = 1e-5;        /* the longest step */
static double dither_amp = 0, dither_period = 0.5;

/* law=gms: the elements (the header comment) */
#define MAX_ELEMENTS 64
static int gms = 0, n_elements = 10;
static double C_attraction = 1000;
static double k_el[MAX_ELEMENTS], alpha_el[MAX_ELEMENTS];
static int mode_el[MAX_ELEMENTS]; /* 0: sticking; +1, −1: slipping that way */

/* law=elastoplastic: the break-away deflection (the header comment) */
static int elastoplastic = 0;
static double z_ba = 0;

/* drive=hold: the actuator's positions, their times, the dithered
   intervals */
#define MAX_HOLD 256
static int hold = 0, n_hold_t = 0, n_hold_x = 0, n_hold_dither = 0, hold_i = 0;
static double hold_t[MAX_HOLD], hold_x[MAX_HOLD], hold_dither[MAX_HOLD];

/* plant=prescribed: a sine, or a path of turning points */
#define MAX_PATH 256
static int prescribed = 0;
static double path[MAX_PATH], speed_list[MAX_PATH], seg_t0[MAX_PATH];
static int n_path = 0, n_speed = 0, seg = 0;

/* splitmix64 */
static uint64_t rng_state;
static double uniform(void) {
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return ((z >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}
static double gaussian(void) {
    return sqrt(-2.0 * log(uniform())) * cos(2.0 * M_PI * uniform());
}

/* The actuator's drive: its parameters drawn from the seed once. */
static double f1, f2, ph1, ph2, a2;
#define MAX_STEPS 4096
static double step_target[MAX_STEPS];
static int n_steps;

static void drive_init(void) {
    f1 = 1.0 / period;
    f2 = f1 * (2.3 + 1.7 * uniform());
    ph1 = 2 * M_PI * uniform();
    ph2 = 2 * M_PI * uniform();
    a2 = 0.15 + 0.25 * uniform();
    n_steps = (int)(duration / (0.5 * period)) + 2;
    if (n_steps > MAX_STEPS) n_steps = MAX_STEPS;
    for (int i = 0; i < n_steps; i++) step_target[i] = amp * (2 * uniform() - 1);
}

static double drive_position(double t) {
    if (strcmp(drive, "triangle") == 0) {
        /* constant speed between ±amp with rounded reversals: a triangle
           wave smoothed as asin(0.98·sin θ) / asin(0.98) */
        return amp * asin(0.98 * sin(2 * M_PI * t / period + ph1)) / asin(0.98) -
               amp * asin(0.98 * sin(ph1)) / asin(0.98);
    }
    if (strcmp(drive, "steps") == 0) {
        /* a new target every half period, reached by a cosine ramp */
        double hp = 0.5 * period;
        int i = (int)(t / hp);
        if (i >= n_steps - 1) i = n_steps - 2;
        double u = t / hp - i;
        double r = u < 0.6 ? 0.5 - 0.5 * cos(M_PI * u / 0.6) : 1.0;
        return step_target[i] + (step_target[i + 1] - step_target[i]) * r;
    }
    return amp * ((1 - a2) * sin(2 * M_PI * f1 * t + ph1) + a2 * sin(2 * M_PI * f2 * t + ph2)) -
           amp * ((1 - a2) * sin(ph1) + a2 * sin(ph2));
}

/* drive=hold at t (the header comment): the interval [t_i, t_(i+1)) that
   holds t is searched from the last one found (the calls come in nearly
   increasing t) */
static double hold_position(double t) {
    int n = n_hold_t;
    if (t <= hold_t[0]) return hold_x[0];
    if (t >= hold_t[n - 1]) return hold_x[n - 1];
    while (hold_i > 0 && t < hold_t[hold_i]) hold_i--;
    while (hold_i < n - 2 && t >= hold_t[hold_i + 1]) hold_i++;
    double t0 = hold_t[hold_i], t1 = hold_t[hold_i + 1];
    double u = (t - t0) / (t1 - t0);
    double xa = hold_x[hold_i] + (hold_x[hold_i + 1] - hold_x[hold_i]) * (u - sin(2 * M_PI * u) / (2 * M_PI));
    if (dither_amp != 0 && hold_i < n_hold_dither && hold_dither[hold_i] != 0) {
        /* faded in over the first dither period, out over the last */
        double tau = t - t0, rest = t1 - t, e = 1;
        if (tau < dither_period) e *= 0.5 * (1 - cos(M_PI * tau / dither_period));
        if (rest < dither_period) e *= 0.5 * (1 - cos(M_PI * rest / dither_period));
        xa += dither_amp * e * sin(2 * M_PI * tau / dither_period);
    }
    return xa;
}

/* the actuator's position: the drive, plus the dither when there is one
   (drive=hold: its own, in its dithered intervals) */
static double actuator(double t) {
    if (hold) return hold_position(t);
    double xa = drive_position(t);
    if (dither_amp != 0) xa += dither_amp * sin(2 * M_PI * t / dither_period);
    return xa;
}

static double position_scale(double x) {
    if (n_table == 0) return 1.0;
    if (x <= x_table[0]) return scale_tab[0];
    for (int i = 1; i < n_table; i++)
        if (x <= x_table[i]) {
            double u = (x - x_table[i - 1]) / (x_table[i] - x_table[i - 1]);
            return scale_tab[i - 1] + u * (scale_tab[i] - scale_tab[i - 1]);
        }
    return scale_tab[n_table - 1];
}

/* g(v, x): the steady-state level */
static double level(double v, double x) {
    double fc = v >= 0 ? Fc : Fc_neg, fs = v >= 0 ? Fs : Fs_neg;
    double r = v / vs;
    return position_scale(x) * (fc + (fs - fc) * exp(-r * r));
}

/* law=elastoplastic: α(z, v) with w = sgn(v)·z, w_ss = g/σ0 (Dupont,
   Hayward, Armstrong and Altpeter 2002, the header comment): 0 up to the
   break-away deflection z_ba (elastic), a half sine up to w_ss, 1 past it
   (LuGre) */
static double ep_alpha(double z, double v, double g) {
    double w = v > 0 ? z : v < 0 ? -z : 0, w_ss = g / sigma0;
    if (w <= z_ba) return 0;
    if (w >= w_ss) return 1;
    return 0.5 * sin(M_PI * (w - 0.5 * (w_ss + z_ba)) / (w_ss - z_ba)) + 0.5;
}

/* the motor force of the two-mass plant */
static double motor_force(double t) {
    return amp * ((1 - a2) * cos(2 * M_PI * f1 * t) + a2 * cos(2 * M_PI * f2 * t));
}

/* the servo's controller force: PD on the motor, tracking actuator(t) */
static double servo_force(double t, const double *y) {
    return Kp * (actuator(t) - y[3]) - Kd * y[4];
}

/* GMS's elements from LuGre's parameters (the header comment) */
static void gms_init(void) {
    double sum = 0;
    for (int i = 0; i < n_elements; i++) {
        k_el[i] = sigma0 / n_elements;
        double slip = -(Fc / sigma0) * log(1 - (i + 0.5) / n_elements); /* Δ_i */
        alpha_el[i] = k_el[i] * slip;
        sum += alpha_el[i];
        mode_el[i] = 0;
    }
    for (int i = 0; i < n_elements; i++) alpha_el[i] /= sum;
}

/* GMS's switches after a step, at the new (x, v): a sticking element at
   or past its level α_i·s(v) is set to it and slips the way v goes; a
   slipping element whose v changed sign or stopped sticks, keeping its
   force (Al-Bender, Lampaert and Swevers 2005) */
static void gms_switch(double x, double v, double *y) {
    double s = level(v, x);
    int dir = (v > 0) - (v < 0);
    for (int i = 0; i < n_elements; i++) {
        double *Fi = &y[5 + i];
        if (mode_el[i] != 0) {
            if (mode_el[i] != dir) mode_el[i] = 0;
        } else if (dir != 0 && dir * *Fi >= alpha_el[i] * s) {
            *Fi = dir * alpha_el[i] * s;
            mode_el[i] = dir;
        }
    }
}

/* where in a step from (x0, v0, y0) to (x1, v1, y1) its first GMS switch
   falls, as a fraction of the step by linear interpolation (1: none): a
   sticking element reaching its level α_i·s(v), or v leaving a slipping
   element's direction */
static double gms_event(double x0, double v0, const double *y0, double x1, double v1, const double *y1) {
    double theta = 1, s0 = level(v0, x0), s1 = level(v1, x1);
    int dir = (v1 > 0) - (v1 < 0);
    for (int i = 0; i < n_elements; i++) {
        if (mode_el[i] != 0) {
            if (mode_el[i] != dir && mode_el[i] * v0 > 0) theta = fmin(theta, v0 / (v0 - v1));
        } else if (dir != 0) {
            double g0 = dir * y0[5 + i] - alpha_el[i] * s0, g1 = dir * y1[5 + i] - alpha_el[i] * s1;
            if (g0 < 0 && g1 >= 0) theta = fmin(theta, g0 / (g0 - g1));
        }
    }
    return theta;
}

/* the prescribed motion at t: a sine, or the path's segment `seg` */
static void motion(double t, double *x, double *v) {
    if (n_path == 0) {
        double w = 2 * M_PI / period;
        *x = amp * sin(w * t);
        *v = amp * w * cos(w * t);
    } else if (seg >= n_path - 1) {
        *x = path[n_path - 1];
        *v = 0;
    } else {
        double dir = path[seg + 1] > path[seg] ? 1 : -1;
        double sp = speed_list[n_speed > 1 ? seg : 0];
        *x = path[seg] + dir * sp * (t - seg_t0[seg]);
        *v = dir * sp;
    }
}

/* past the path's turning points up to t (the segments of no length too) */
static void advance_segment(double t) {
    while (n_path > 0 && seg < n_path - 1 && seg_t0[seg + 1] <= t) seg++;
}

/* the friction force at (x, v); its states' rates into dy (z: dy[2];
   GMS: dy[5 + i], the modes held) */
static double friction(double x, double v, const double *y, double *dy) {
    if (elastoplastic) {
        /* z' = v − α(z, v)·σ0·|v|·z/g(v), F = σ0·z + σ1·z' + σ2·v */
        double z = y[2], g = level(v, x);
        double zd = v - ep_alpha(z, v, g) * sigma0 * fabs(v) * z / g;
        dy[2] = zd;
        return sigma0 * z + sigma1 * zd + sigma2 * v;
    }
    if (!gms) {
        double z = y[2];
        double zd = v - sigma0 * fabs(v) * z / level(v, x);
        dy[2] = zd;
        return sigma0 * z + sigma1 * zd + sigma2 * v;
    }
    /* GMS: sticking dF_i/dt = k_i·v, slipping dF_i/dt = C·(sgn(v)·α_i −
       F_i/s(v)); F = Σ F_i + (σ1/σ0)·Σ dF_i/dt + σ2·v */
    double s = level(v, x), F = 0, rate = 0;
    for (int i = 0; i < n_elements; i++) {
        double d = mode_el[i] == 0 ? k_el[i] * v : C_attraction * (mode_el[i] * alpha_el[i] - y[5 + i] / s);
        dy[5 + i] = d;
        F += y[5 + i];
        rate += d;
    }
    dy[2] = 0;
    return F + sigma1 / sigma0 * rate + sigma2 * v;
}

/* state y = (x, v, z, x_m, v_m[, F_1..F_N]); returns the friction force */
static double rhs(double t, const double *y, double *dy) {
    if (prescribed) {
        double xp, vp;
        motion(t, &xp, &vp);
        dy[0] = dy[1] = dy[3] = dy[4] = 0;
        return friction(xp, vp, y, dy);
    }
    double x = y[0], v = y[1];
    double F = friction(x, v, y, dy);
    dy[0] = v;
    if (two_mass || servo) {
        double belt = k * (y[3] - x) + c * (y[4] - v);
        double u = servo ? servo_force(t, y) : motor_force(t);
        dy[1] = (belt - F) / m;
        dy[3] = y[4];
        dy[4] = (u - belt - c_m * y[4]) / m_m;
    } else {
        dy[1] = (k * (actuator(t) - x) - c * v - F) / m;
        dy[3] = dy[4] = 0;
    }
    return F;
}

static int parse_list(const char *s, double *out, int max) {
    int n = 0;
    while (*s && n < max) {
        char *end;
        out[n++] = strtod(s, &end);
        if (*end != ',') break;
        s = end + 1;
    }
    return n;
}

static double quantise(double x) {
    if (noise > 0) x += noise * gaussian();
    return resolution > 0 ? resolution * nearbyint(x / resolution) : x;
}

int main(int argc, char **argv) {
    for (int i = 1; i < argc; i++) {
        char *eq = strchr(argv[i], '=');
        if (!eq) {
            fprintf(stderr, "lugre_rig: argument `%s` is not key=value\n", argv[i]);
            return 2;
        }
        *eq = 0;
        const char *key = argv[i], *val = eq + 1;
        double d = atof(val);
#define KEY(name, var) else if (strcmp(key, name) == 0) var = d;
        if (0) {}
        KEY("m", m) KEY("c", c) KEY("k", k) KEY("Fc", Fc) KEY("Fs", Fs)
        KEY("Fc_neg", Fc_neg) KEY("Fs_neg", Fs_neg) KEY("vs", vs)
        KEY("sigma0", sigma0) KEY("sigma1", sigma1) KEY("sigma2", sigma2)
        KEY("duration", duration) KEY("sample", sample)
        KEY("resolution", resolution) KEY("noise", noise) KEY("amp", amp)
        KEY("period", period) KEY("step_fraction", step_fraction) KEY("h_max", h_max)
        KEY("m_m", m_m) KEY("c_m", c_m) KEY("Kp", Kp) KEY("Kd", Kd)
        KEY("force_resolution", force_resolution)
        KEY("dither_amp", dither_amp) KEY("dither_period", dither_period)
        KEY("C", C_attraction) KEY("z_ba", z_ba)
        else if (strcmp(key, "plant") == 0) {
            two_mass = strcmp(val, "two_mass") == 0;
            servo = strcmp(val, "servo") == 0;
            prescribed = strcmp(val, "prescribed") == 0;
            if (!two_mass && !servo && !prescribed && strcmp(val, "rig") != 0) {
                fprintf(stderr, "lugre_rig: unknown plant `%s`\n", val);
                return 2;
            }
        }
        else if (strcmp(key, "seed") == 0) seed = strtoull(val, NULL, 10);
        else if (strcmp(key, "truth") == 0) write_truth = atoi(val);
        else if (strcmp(key, "drive") == 0) snprintf(drive, sizeof drive, "%s", val);
        else if (strcmp(key, "x_table") == 0) n_table = parse_list(val, x_table, MAX_TABLE);
        else if (strcmp(key, "scale") == 0) parse_list(val, scale_tab, MAX_TABLE);
        else if (strcmp(key, "path") == 0) n_path = parse_list(val, path, MAX_PATH);
        else if (strcmp(key, "speed") == 0) n_speed = parse_list(val, speed_list, MAX_PATH);
        else if (strcmp(key, "n_elements") == 0) n_elements = atoi(val);
        else if (strcmp(key, "hold_t") == 0) n_hold_t = parse_list(val, hold_t, MAX_HOLD);
        else if (strcmp(key, "hold_x") == 0) n_hold_x = parse_list(val, hold_x, MAX_HOLD);
        else if (strcmp(key, "hold_dither") == 0) n_hold_dither = parse_list(val, hold_dither, MAX_HOLD);
        else if (strcmp(key, "law") == 0) {
            gms = strcmp(val, "gms") == 0;
            elastoplastic = strcmp(val, "elastoplastic") == 0;
            if (!gms && !elastoplastic && strcmp(val, "lugre") != 0) {
                fprintf(stderr, "lugre_rig: unknown law `%s`\n", val);
                return 2;
            }
        }
        else {
            fprintf(stderr, "lugre_rig: unknown key `%s`\n", key);
            return 2;
        }
    }
    if (Fc_neg < 0) Fc_neg = Fc;
    if (Fs_neg < 0) Fs_neg = Fs;
    if (m <= 0 || k < 0 || Fc <= 0 || sigma0 <= 0 || vs <= 0 || sample <= 0 || duration <= 0) {
        fprintf(stderr, "lugre_rig: m, Fc, sigma0, vs, sample and duration must be positive\n");
        return 2;
    }
    if (gms && (n_elements < 1 || n_elements > MAX_ELEMENTS || C_attraction <= 0)) {
        fprintf(stderr, "lugre_rig: law=gms needs 1 <= n_elements <= %d and C > 0\n", MAX_ELEMENTS);
        return 2;
    }
    if (elastoplastic) {
        if ((Fc_neg != Fc || Fs_neg != Fs) || n_table > 0) {
            fprintf(stderr, "lugre_rig: law=elastoplastic takes one pair of levels (no Fc_neg, Fs_neg) and no "
                            "position table\n");
            return 2;
        }
        if (!(z_ba >= 0 && z_ba < fmin(Fc, Fs) / sigma0)) {
            fprintf(stderr, "lugre_rig: law=elastoplastic needs 0 <= z_ba < min(Fc, Fs)/sigma0 = %g m\n",
                    fmin(Fc, Fs) / sigma0);
            return 2;
        }
    }
    hold = strcmp(drive, "hold") == 0;
    if (hold) {
        int ok = n_hold_t >= 2 && n_hold_x == n_hold_t && (n_hold_dither == 0 || n_hold_dither == n_hold_t - 1);
        for (int i = 0; ok && i + 1 < n_hold_t; i++) ok = hold_t[i + 1] > hold_t[i];
        if (!ok) {
            fprintf(stderr, "lugre_rig: drive=hold needs hold_t (two or more, increasing), hold_x as many and "
                            "hold_dither one per interval (or none)\n");
            return 2;
        }
    }
    if (dither_amp != 0 && dither_period <= 0) {
        fprintf(stderr, "lugre_rig: dither_period must be positive\n");
        return 2;
    }
    if (prescribed && n_path > 0) {
        if (n_path < 2 || n_speed < 1 || (n_speed > 1 && n_speed < n_path - 1)) {
            fprintf(stderr, "lugre_rig: path needs two points or more and a speed (one, or one per segment)\n");
            return 2;
        }
        seg_t0[0] = 0;
        for (int i = 0; i + 1 < n_path; i++) {
            double sp = speed_list[n_speed > 1 ? i : 0];
            if (sp <= 0) {
                fprintf(stderr, "lugre_rig: speed must be positive\n");
                return 2;
            }
            seg_t0[i + 1] = seg_t0[i] + fabs(path[i + 1] - path[i]) / sp;
        }
    }
    if (gms) gms_init();
    rng_state = seed * 0x2545F4914F6CDD1Dull + 17;
    drive_init();

    /* the step, chosen before each step from the state: a fraction of the
       contact's stiffest time scale (the bristle-mass period √(m/σ0), the
       bristle relaxation g/(σ0·|v|) while sliding, m/σ1), at most h_max
       (1e-5 s) */
    double h_cap = fmin(h_max, step_fraction * sqrt(m / sigma0));
    if (sigma1 > 0) h_cap = fmin(h_cap, step_fraction * m / sigma1);

    /* start at rest, the spring relaxed, no bristle deflection (GMS: every
       element sticking, unloaded) */
    enum { NY = 5 + MAX_ELEMENTS };
    int ny = gms ? 5 + n_elements : 5;
    double y[NY] = {two_mass ? 0.0 : actuator(0.0), 0, 0, servo ? actuator(0.0) : 0.0, 0};
    double k1[NY], k2[NY], k3[NY], k4[NY], yt[NY], yn[NY];
    if (prescribed) {
        advance_segment(0.0);
        motion(0.0, &y[0], &y[1]);
    }
    if (two_mass || servo) h_cap = fmin(h_cap, step_fraction * sqrt(fmin(m, m_m) / (k + 1e-300)));
    /* the controller: its stiffness on the motor, and its damping */
    if (servo) h_cap = fmin(h_cap, step_fraction * fmin(sqrt(m_m / (Kp + 1e-300)), m_m / (Kd + 1e-300)));
    long n = (long)llround(duration / sample);
    if (prescribed)
        printf("time,true_x,true_F\n");
    else if (two_mass)
        printf("time,drive.u,drive.x_m,drive.x_l%s\n", write_truth ? ",true_x,true_F" : "");
    else if (servo)
        printf("time,drive.r,drive.x_m,drive.x_l,drive.u%s\n", write_truth ? ",true_x,true_F" : "");
    else
        printf("time,rig.x_act_in,rig.x%s\n", write_truth ? ",true_x,true_F" : "");
    for (long s = 0; s <= n; s++) {
        double t = s * sample;
        double F = rhs(t, y, k1);
        if (prescribed) {
            double xp, vp;
            motion(t, &xp, &vp);
            printf("%.6f,%.12g,%.12g\n", t, xp, F);
        } else if (two_mass || servo) {
            if (two_mass) printf("%.6f,%.9g,%.9g,%.9g", t, motor_force(t), quantise(y[3]), quantise(y[0]));
            else {
                double u = servo_force(t, y);
                if (force_resolution > 0) u = force_resolution * nearbyint(u / force_resolution);
                printf("%.6f,%.12g,%.9g,%.9g,%.9g", t, actuator(t), quantise(y[3]), quantise(y[0]), u);
            }
            if (write_truth) printf(",%.12g,%.9g", y[0], F);
            printf("\n");
        } else if (write_truth)
            printf("%.6f,%.9g,%.9g,%.12g,%.9g\n", t, quantise(actuator(t)), quantise(y[0]), y[0], F);
        else
            printf("%.6f,%.9g,%.9g\n", t, quantise(actuator(t)), quantise(y[0]));
        if (s == n) break;
        double tj = t, t_next = (s + 1) * sample;
        while (tj < t_next) {
            /* a prescribed path's next turning point: the steps land on it */
            double t_break = prescribed && n_path > 0 && seg < n_path - 1 ? seg_t0[seg + 1] : INFINITY;
            double t_stop = fmin(t_next, t_break);
            double h = fmin(h_cap, t_stop - tj);
            double x0 = y[0], v0 = y[1];
            if (prescribed) motion(tj, &x0, &v0);
            if (!gms) {
                double relax = step_fraction * level(v0, x0) / (sigma0 * fabs(v0) + 1e-300);
                if (relax < h) h = relax;
                if (elastoplastic) {
                    /* the sine of α: ∂z'/∂z is at most (π/2)·|v|/(w_ss − z_ba) there */
                    double sine = step_fraction * (2 / M_PI) * (level(v0, x0) / sigma0 - z_ba) / (fabs(v0) + 1e-300);
                    if (sine < h) h = sine;
                }
            } else {
                /* the slipping elements' relaxation time s/C, and a small
                   part of each sticking element's slip distance α_i·s/k_i */
                double s = level(v0, x0);
                double hg = step_fraction * s / C_attraction;
                for (int i = 0; i < n_elements; i++)
                    if (mode_el[i] == 0 && v0 != 0)
                        hg = fmin(hg, 0.1 * step_fraction * alpha_el[i] * s / (k_el[i] * fabs(v0)));
                if (hg < h) h = hg;
            }
            if (t_stop - tj - h < 1e-3 * h) h = t_stop - tj;
            double h0 = h;
            for (;;) {
                rhs(tj, y, k1);
                for (int i = 0; i < ny; i++) yt[i] = y[i] + 0.5 * h * k1[i];
                rhs(tj + 0.5 * h, yt, k2);
                for (int i = 0; i < ny; i++) yt[i] = y[i] + 0.5 * h * k2[i];
                rhs(tj + 0.5 * h, yt, k3);
                for (int i = 0; i < ny; i++) yt[i] = y[i] + h * k3[i];
                rhs(tj + h, yt, k4);
                for (int i = 0; i < ny; i++) yn[i] = y[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
                if (!gms) break;
                /* GMS: a switch inside the step (a sticking element
                   reaching its level, v changing sign under a slipping
                   one) is located by linear interpolation and the step
                   taken again to end just past it, within 0.5 % of the
                   step: the switches then fall on step ends */
                double x1 = yn[0], v1 = yn[1];
                if (prescribed) motion(tj + h, &x1, &v1);
                double theta = gms_event(x0, v0, y, x1, v1, yn);
                if ((1 - theta) * h <= 5e-3 * h0) break;
                h = theta * h + 2.5e-3 * h0;
            }
            for (int i = 0; i < ny; i++) y[i] = yn[i];
            if (h == t_stop - tj && t_stop == t_break) {
                tj = t_break;
                advance_segment(tj);
            } else
                tj += h;
            if (prescribed) motion(tj, &y[0], &y[1]);
            if (gms) gms_switch(y[0], y[1], y);
        }
        int finite = 1;
        for (int i = 0; i < ny; i++) finite = finite && isfinite(y[i]);
        if (!finite) {
            fprintf(stderr, "lugre_rig: the state is not finite at t = %g s\n", t);
            return 1;
        }
    }
    return 0;
}
