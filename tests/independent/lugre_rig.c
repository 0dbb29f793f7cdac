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
 * min(√(m/σ0), m/σ1, g/(σ0·|v|)), at most 1e-5 s, landing on every sample
 * time. Halving the fraction moves the samples by far less than the 1 µm
 * encoder step (checked by tests/test_independent_rig.py). Sampling: every `sample` seconds; the mass and the
 * actuator are read through an encoder (Gaussian noise of `noise` m, then
 * rounded to `resolution` m).
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
 * Usage: lugre_rig key=value ... > data.csv
 *   keys: m c k Fc Fs Fc_neg Fs_neg vs sigma0 sigma1 sigma2 duration
 *         sample resolution noise seed drive (sines|triangle|steps)
 *         amp period  n_table x_table scale (comma lists)
 *         plant (rig|two_mass|servo)  m_m c_m (two_mass, servo)  Kp Kd
 *         force_resolution (servo)
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

static double actuator(double t) {
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

/* the motor force of the two-mass plant */
static double motor_force(double t) {
    return amp * ((1 - a2) * cos(2 * M_PI * f1 * t) + a2 * cos(2 * M_PI * f2 * t));
}

/* the servo's controller force: PD on the motor, tracking actuator(t) */
static double servo_force(double t, const double *y) {
    return Kp * (actuator(t) - y[3]) - Kd * y[4];
}

/* state y = (x, v, z[, x_m, v_m]); returns the friction force */
static double rhs(double t, const double *y, double *dy) {
    double x = y[0], v = y[1], z = y[2];
    double zd = v - sigma0 * fabs(v) * z / level(v, x);
    double F = sigma0 * z + sigma1 * zd + sigma2 * v;
    dy[0] = v;
    dy[2] = zd;
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

static int parse_list(const char *s, double *out) {
    int n = 0;
    while (*s && n < MAX_TABLE) {
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
        KEY("period", period) KEY("step_fraction", step_fraction)
        KEY("m_m", m_m) KEY("c_m", c_m) KEY("Kp", Kp) KEY("Kd", Kd)
        KEY("force_resolution", force_resolution)
        else if (strcmp(key, "plant") == 0) {
            two_mass = strcmp(val, "two_mass") == 0;
            servo = strcmp(val, "servo") == 0;
            if (!two_mass && !servo && strcmp(val, "rig") != 0) {
                fprintf(stderr, "lugre_rig: unknown plant `%s`\n", val);
                return 2;
            }
        }
        else if (strcmp(key, "seed") == 0) seed = strtoull(val, NULL, 10);
        else if (strcmp(key, "truth") == 0) write_truth = atoi(val);
        else if (strcmp(key, "drive") == 0) snprintf(drive, sizeof drive, "%s", val);
        else if (strcmp(key, "x_table") == 0) n_table = parse_list(val, x_table);
        else if (strcmp(key, "scale") == 0) parse_list(val, scale_tab);
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
    rng_state = seed * 0x2545F4914F6CDD1Dull + 17;
    drive_init();

    /* the step, chosen before each step from the state: a fraction of the
       contact's stiffest time scale (the bristle-mass period √(m/σ0), the
       bristle relaxation g/(σ0·|v|) while sliding, m/σ1), at most 1e-5 s */
    double h_cap = fmin(1e-5, step_fraction * sqrt(m / sigma0));
    if (sigma1 > 0) h_cap = fmin(h_cap, step_fraction * m / sigma1);

    /* start at rest, the spring relaxed, no bristle deflection */
    double y[5] = {two_mass ? 0.0 : actuator(0.0), 0, 0, servo ? actuator(0.0) : 0.0, 0};
    double k1[5], k2[5], k3[5], k4[5], yt[5];
    if (two_mass || servo) h_cap = fmin(h_cap, step_fraction * sqrt(fmin(m, m_m) / (k + 1e-300)));
    /* the controller: its stiffness on the motor, and its damping */
    if (servo) h_cap = fmin(h_cap, step_fraction * fmin(sqrt(m_m / (Kp + 1e-300)), m_m / (Kd + 1e-300)));
    long n = (long)llround(duration / sample);
    if (two_mass)
        printf("time,drive.u,drive.x_m,drive.x_l%s\n", write_truth ? ",true_x,true_F" : "");
    else if (servo)
        printf("time,drive.r,drive.x_m,drive.x_l,drive.u%s\n", write_truth ? ",true_x,true_F" : "");
    else
        printf("time,rig.x_act_in,rig.x%s\n", write_truth ? ",true_x,true_F" : "");
    for (long s = 0; s <= n; s++) {
        double t = s * sample;
        double F = rhs(t, y, k1);
        if (two_mass || servo) {
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
            double h = fmin(h_cap, t_next - tj);
            double relax = step_fraction * level(y[1], y[0]) / (sigma0 * fabs(y[1]) + 1e-300);
            if (relax < h) h = relax;
            if (t_next - tj - h < 1e-3 * h) h = t_next - tj;
            rhs(tj, y, k1);
            for (int i = 0; i < 5; i++) yt[i] = y[i] + 0.5 * h * k1[i];
            rhs(tj + 0.5 * h, yt, k2);
            for (int i = 0; i < 5; i++) yt[i] = y[i] + 0.5 * h * k2[i];
            rhs(tj + 0.5 * h, yt, k3);
            for (int i = 0; i < 5; i++) yt[i] = y[i] + h * k3[i];
            rhs(tj + h, yt, k4);
            for (int i = 0; i < 5; i++) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
            tj += h;
        }
        if (!isfinite(y[0]) || !isfinite(y[1]) || !isfinite(y[2]) || !isfinite(y[3]) || !isfinite(y[4])) {
            fprintf(stderr, "lugre_rig: the state is not finite at t = %g s\n", t);
            return 1;
        }
    }
    return 0;
}
