/* A small FMI 3.0 Co-Simulation importer for tests/test_windows_dll.py,
 * the FMI 3.0 twin of fmi_driver.c: the same source is compiled for
 * Windows with x86_64-w64-mingw32-gcc and run under Wine against
 * binaries/x86_64-windows/<model>.dll of dist/fmi3/<Name>.fmu (LoadLibrary,
 * GetProcAddress), and compiled natively with gcc against
 * binaries/x86_64-linux/<model>.so (dlopen, dlsym); the two outputs are
 * compared with each other and with fmi_driver.c's FMI 2.0 run.
 *
 *   fmi3_driver LIBRARY PLAN RESOURCE_PATH
 *
 * PLAN is fmi_driver.c's plan (the value references of the FMI 2.0 and
 * FMI 3.0 descriptions are the same; `guid` is the instantiation token,
 * `real` a Float64, `integer` an Int32), and one more directive:
 *
 *   reals VR N BITS1 ... BITSN    a Float64 array parameter of N elements
 *
 * Printed on stdout: `o T Y1 ... Ym`
 * (reals as the 16 hexadecimal digits of their bits) after each step, each
 * log message as `log STATUS CATEGORY MESSAGE`, each misuse as
 * `check NAME GOT EXPECTED ok|FAILED`. A few calls are made wrongly on
 * purpose (wrong state, NULL instance, unknown value reference, NaN input,
 * nValues that does not match, wrong token); each must be refused. The
 * exit status is 0 when every call returned what it must, 1 otherwise, 2
 * for a usage error. */
#define __USE_MINGW_ANSI_STDIO 1 /* C99 printf and strtoull under MinGW */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Library;
static Library open_library(const char *path) { return LoadLibraryA(path); }
static void *symbol(Library lib, const char *name) {
    return (void *)GetProcAddress(lib, name);
}
static void print_load_error(const char *path) {
    fprintf(stderr, "LoadLibrary %s failed: error %lu\n", path, (unsigned long)GetLastError());
}
#else
#include <dlfcn.h>
typedef void *Library;
static Library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(Library lib, const char *name) { return dlsym(lib, name); }
static void print_load_error(const char *path) {
    fprintf(stderr, "dlopen %s failed: %s\n", path, dlerror());
}
#endif

/* ---- the FMI 3.0 types this driver uses (fmi3PlatformTypes.h) ---- */
typedef void *fmi3Instance;
typedef uint32_t fmi3ValueReference;
typedef int fmi3Status; /* fmi3OK = 0, fmi3Error = 3 */
enum { fmi3OK = 0, fmi3Error = 3 };
typedef void (*LogMessageF)(void *, fmi3Status, const char *, const char *);

typedef const char *(*GetVersionF)(void);
typedef fmi3Instance (*InstantiateF)(const char *, const char *, const char *, bool, bool, bool,
                                     bool, const fmi3ValueReference *, size_t, void *,
                                     LogMessageF, void *);
typedef void (*FreeInstanceF)(fmi3Instance);
typedef fmi3Status (*EnterInitF)(fmi3Instance, bool, double, double, bool, double);
typedef fmi3Status (*InstanceF)(fmi3Instance);
typedef fmi3Status (*SetF64)(fmi3Instance, const fmi3ValueReference *, size_t, const double *,
                             size_t);
typedef fmi3Status (*GetF64)(fmi3Instance, const fmi3ValueReference *, size_t, double *, size_t);
typedef fmi3Status (*SetI32)(fmi3Instance, const fmi3ValueReference *, size_t, const int32_t *,
                             size_t);
typedef fmi3Status (*GetI32)(fmi3Instance, const fmi3ValueReference *, size_t, int32_t *, size_t);
typedef fmi3Status (*SetBool)(fmi3Instance, const fmi3ValueReference *, size_t, const bool *,
                              size_t);
typedef fmi3Status (*GetBool)(fmi3Instance, const fmi3ValueReference *, size_t, bool *, size_t);
typedef fmi3Status (*DoStepF)(fmi3Instance, double, double, bool, bool *, bool *, bool *,
                              double *);

static struct {
    GetVersionF get_version;
    InstantiateF instantiate;
    FreeInstanceF free_instance;
    EnterInitF enter_initialization_mode;
    InstanceF exit_initialization_mode, terminate;
    SetF64 set_float64;
    GetF64 get_float64;
    SetI32 set_int32;
    GetI32 get_int32;
    SetBool set_boolean;
    GetBool get_boolean;
    DoStepF do_step;
} fmi;

static void *require(Library lib, const char *name) {
    void *f = symbol(lib, name);
    if (!f) {
        fprintf(stderr, "the library does not export %s\n", name);
        exit(2);
    }
    return f;
}

/* ---- logging and checks ---- */
static void log_message(void *env, fmi3Status status, const char *category, const char *message) {
    (void)env;
    printf("log %d %s %s\n", status, category, message);
}

static int failures;
static void check(const char *name, long got, long expected) {
    printf("check %s %ld %ld %s\n", name, got, expected, got == expected ? "ok" : "FAILED");
    if (got != expected) failures++;
}

static uint64_t bits_of(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}
static double real_of(const char *hex) {
    uint64_t u = strtoull(hex, NULL, 16);
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* ---- the plan ---- */
#define MAX_VARS 256
static char token[256];
static fmi3ValueReference inputs[MAX_VARS], outputs[MAX_VARS];
static char output_types[MAX_VARS]; /* 'r', 'i', 'b' */
static size_t n_inputs, n_outputs;
static fmi3ValueReference nan_input;
static int has_nan_input;

static fmi3Instance instantiate(const char *the_token, const char *resources) {
    return fmi.instantiate("driver", the_token, resources, false, false, false, false, NULL, 0,
                           NULL, log_message, NULL);
}

static fmi3Status step(fmi3Instance c, double t, double h, double *last) {
    bool event = true, terminate = true, early = true;
    fmi3Status s = fmi.do_step(c, t, h, true, &event, &terminate, &early, last);
    if (s == fmi3OK && (event || terminate || early)) check("do_step_flags_clear", 1, 0);
    return s;
}

/* Wrong calls mid-run: an unknown value reference, NaN for an input (the
 * input keeps its value), nValues other than the number of scalars, a
 * NULL instance. */
static void misuse_mid_run(fmi3Instance c) {
    const fmi3ValueReference unknown = 0x7fffffffu;
    double x[2] = {1.0, 1.0}, last = 0.0;
    check("set_float64_unknown_vr", fmi.set_float64(c, &unknown, 1, x, 1), fmi3Error);
    check("get_float64_unknown_vr", fmi.get_float64(c, &unknown, 1, x, 1), fmi3Error);
    check("get_float64_nvalues_mismatch", fmi.get_float64(c, &outputs[0], 1, x, 2), fmi3Error);
    check("get_float64_null_instance", fmi.get_float64(NULL, &outputs[0], 1, x, 1), fmi3Error);
    check("do_step_null_instance", step(NULL, 0.0, 1e-3, &last), fmi3Error);
    if (has_nan_input) {
        double before, after, nan = NAN;
        check("get_input_before_nan", fmi.get_float64(c, &nan_input, 1, &before, 1), fmi3OK);
        check("set_float64_nan_input", fmi.set_float64(c, &nan_input, 1, &nan, 1), fmi3Error);
        check("get_input_after_nan", fmi.get_float64(c, &nan_input, 1, &after, 1), fmi3OK);
        check("nan_left_input_unchanged", bits_of(after) == bits_of(before), 1);
    }
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: %s LIBRARY PLAN RESOURCE_PATH\n", argv[0]);
        return 2;
    }
    Library lib = open_library(argv[1]);
    if (!lib) {
        print_load_error(argv[1]);
        return 2;
    }
    fmi.get_version = (GetVersionF)require(lib, "fmi3GetVersion");
    fmi.instantiate = (InstantiateF)require(lib, "fmi3InstantiateCoSimulation");
    fmi.free_instance = (FreeInstanceF)require(lib, "fmi3FreeInstance");
    fmi.enter_initialization_mode = (EnterInitF)require(lib, "fmi3EnterInitializationMode");
    fmi.exit_initialization_mode = (InstanceF)require(lib, "fmi3ExitInitializationMode");
    fmi.terminate = (InstanceF)require(lib, "fmi3Terminate");
    fmi.set_float64 = (SetF64)require(lib, "fmi3SetFloat64");
    fmi.get_float64 = (GetF64)require(lib, "fmi3GetFloat64");
    fmi.set_int32 = (SetI32)require(lib, "fmi3SetInt32");
    fmi.get_int32 = (GetI32)require(lib, "fmi3GetInt32");
    fmi.set_boolean = (SetBool)require(lib, "fmi3SetBoolean");
    fmi.get_boolean = (GetBool)require(lib, "fmi3GetBoolean");
    fmi.do_step = (DoStepF)require(lib, "fmi3DoStep");
    printf("version %s\nplatform fmi3\n", fmi.get_version());

    FILE *plan = fopen(argv[2], "r");
    if (!plan) {
        fprintf(stderr, "cannot open %s\n", argv[2]);
        return 2;
    }
    char line[8192];
    fmi3Instance c = NULL;
    double t = 0.0, last = 0.0;
    long steps = 0, line_no = 0;
    int initialized = 0, checked_mid_run = 0;
    long mid_run = -1; /* the step before which misuse_mid_run runs */
    while (fgets(line, sizeof line, plan)) {
        char *word = strtok(line, " \t\r\n");
        line_no++;
        if (!word || word[0] == '#') continue;
        if (!strcmp(word, "guid")) {
            snprintf(token, sizeof token, "%s", strtok(NULL, " \t\r\n"));
            /* A token this library does not hold: refused. */
            fmi3Instance wrong = instantiate("{00000000-0000-0000-0000-000000000000}", argv[3]);
            check("instantiate_wrong_token_is_null", wrong == NULL, 1);
            c = instantiate(token, argv[3]);
            check("instantiate", c != NULL, 1);
            if (!c) return 1;
            /* Wrong state: no step and no exit before initialization. */
            check("do_step_before_initialization", step(c, 0.0, 1e-3, &last), fmi3Error);
            check("exit_initialization_before_enter", fmi.exit_initialization_mode(c), fmi3Error);
        } else if (!c) {
            fprintf(stderr, "%s:%ld: the plan must start with its guid\n", argv[2], line_no);
            return 2;
        } else if (!strcmp(word, "real") || !strcmp(word, "integer") || !strcmp(word, "boolean")) {
            fmi3ValueReference vr = (fmi3ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
            const char *value = strtok(NULL, " \t\r\n");
            fmi3Status s;
            if (word[0] == 'r') {
                double x = real_of(value);
                s = fmi.set_float64(c, &vr, 1, &x, 1);
            } else if (word[0] == 'i') {
                int32_t n = atoi(value);
                s = fmi.set_int32(c, &vr, 1, &n, 1);
            } else {
                bool b = atoi(value) != 0;
                s = fmi.set_boolean(c, &vr, 1, &b, 1);
            }
            check("set_parameter", s, fmi3OK);
        } else if (!strcmp(word, "reals")) {
            fmi3ValueReference vr = (fmi3ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
            size_t n = (size_t)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
            double x[MAX_VARS];
            if (n > MAX_VARS) {
                fprintf(stderr, "%s:%ld: more than %d elements\n", argv[2], line_no, MAX_VARS);
                return 2;
            }
            for (size_t i = 0; i < n; i++) x[i] = real_of(strtok(NULL, " \t\r\n"));
            check("set_array_parameter", fmi.set_float64(c, &vr, 1, x, n), fmi3OK);
        } else if (!strcmp(word, "input")) {
            inputs[n_inputs++] = (fmi3ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
        } else if (!strcmp(word, "output")) {
            const char *type = strtok(NULL, " \t\r\n");
            output_types[n_outputs] = type[0];
            outputs[n_outputs++] = (fmi3ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
        } else if (!strcmp(word, "nan_input")) {
            nan_input = (fmi3ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
            has_nan_input = 1;
        } else if (!strcmp(word, "steps")) {
            mid_run = strtol(strtok(NULL, " \t\r\n"), NULL, 10) / 2;
        } else if (!strcmp(word, "step")) {
            double h = real_of(strtok(NULL, " \t\r\n")), u[MAX_VARS];
            if (!initialized) {
                check("enter_initialization_mode",
                      fmi.enter_initialization_mode(c, false, 0.0, 0.0, false, 0.0), fmi3OK);
                check("exit_initialization_mode", fmi.exit_initialization_mode(c), fmi3OK);
                initialized = 1;
            }
            for (size_t i = 0; i < n_inputs; i++) u[i] = real_of(strtok(NULL, " \t\r\n"));
            if (n_inputs && fmi.set_float64(c, inputs, n_inputs, u, n_inputs) != fmi3OK)
                check("set_inputs", 1, 0);
            if (steps == mid_run) {
                misuse_mid_run(c);
                checked_mid_run = 1;
            }
            if (step(c, t, h, &last) != fmi3OK) {
                printf("do_step at t = %.17g failed\n", t);
                check("do_step", 1, 0);
                break;
            }
            t += h;
            steps++;
            if (bits_of(last) != bits_of(t)) check("last_successful_time_is_the_end", 0, 1);
            printf("o %016llx", (unsigned long long)bits_of(t));
            for (size_t i = 0; i < n_outputs; i++) {
                double y = NAN;
                int32_t n = 0;
                bool b = false;
                fmi3Status s = output_types[i] == 'r'   ? fmi.get_float64(c, &outputs[i], 1, &y, 1)
                               : output_types[i] == 'i' ? fmi.get_int32(c, &outputs[i], 1, &n, 1)
                                                        : fmi.get_boolean(c, &outputs[i], 1, &b, 1);
                if (s != fmi3OK) check("get_output", s, fmi3OK);
                if (output_types[i] == 'r')
                    printf(" %016llx", (unsigned long long)bits_of(y));
                else
                    printf(" %d", output_types[i] == 'i' ? (int)n : (int)b);
            }
            printf("\n");
        } else {
            fprintf(stderr, "%s:%ld: unknown directive %s\n", argv[2], line_no, word);
            return 2;
        }
    }
    fclose(plan);
    if (!c) {
        fprintf(stderr, "%s: no guid\n", argv[2]);
        return 2;
    }
    check("misused_mid_run", checked_mid_run, 1);
    check("terminate", fmi.terminate(c), fmi3OK);
    fmi.free_instance(c);
    printf("steps %ld\nfailures %d\n", steps, failures);
    return failures ? 1 : 0;
}
