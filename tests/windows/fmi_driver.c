/* A small FMI 2.0 Co-Simulation importer for tests/test_windows_dll.py:
 * the same source is compiled for Windows with x86_64-w64-mingw32-gcc and
 * run under Wine against binaries/win64/<model>.dll (LoadLibrary,
 * GetProcAddress), and compiled natively with gcc against
 * binaries/linux64/<model>.so (dlopen, dlsym), and the two outputs are
 * compared.
 *
 *   fmi_driver LIBRARY PLAN RESOURCE_URI [URI...]
 *
 * PLAN is a text file, one directive a line (reals as the 16 hexadecimal
 * digits of their IEEE 754 bits, so both platforms read and write exactly
 * the same numbers, whatever their C library's printf and strtod do):
 *
 *   guid {...}                    the GUID of modelDescription.xml
 *   real VR BITS                  a Real parameter, set after instantiation
 *   integer VR N                  an Integer parameter
 *   boolean VR 0|1                a Boolean parameter
 *   input VR                      a Real input (the order of the step columns)
 *   output real|integer|boolean VR   recorded after every step
 *   nan_input VR                  the Real input the NaN misuse sets
 *   steps N                       the number of step lines (the misuse of
 *                                 a running instance comes before step N/2)
 *   step H U1 ... Un              one communication step of length H with
 *                                 the inputs set to U1 ... Un first
 *
 * The instance is created with fmuResourceLocation RESOURCE_URI; every
 * further URI is tried in an instance of its own with logging on, which
 * must be created. Printed on stdout: `o T Y1 ... Ym` (bits) after each
 * step, each log message as `log STATUS CATEGORY MESSAGE`, each misuse as
 * `check NAME GOT EXPECTED ok|FAILED`. A few calls are made wrongly on
 * purpose (wrong state, NULL component, unknown value reference, NaN
 * input, wrong GUID); each must be refused. Mid-run, a second thread
 * reads the first output 40 times and ends before the run goes on: the
 * instance changes threads twice (its guard's bias, earned by the calls
 * of one thread, is taken away with a process-wide barrier:
 * FlushProcessWriteBuffers on Windows, membarrier on Linux), and every
 * call must be admitted and read the same value. The exit status is 0 when
 * every call returned what it must, 1 otherwise, 2 for a usage error. */
#define __USE_MINGW_ANSI_STDIO 1 /* C99 printf and strtoull under MinGW */
#include <math.h>
#include <stdarg.h>
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
/* one function run on a thread of its own, waited for */
typedef struct {
    void (*run)(void *);
    void *arg;
} ThreadJob;
static DWORD WINAPI thread_start(LPVOID job) {
    ((ThreadJob *)job)->run(((ThreadJob *)job)->arg);
    return 0;
}
static int on_another_thread(void (*run)(void *), void *arg) {
    ThreadJob job = {run, arg};
    HANDLE t = CreateThread(NULL, 0, thread_start, &job, 0, NULL);
    if (!t) return 0;
    WaitForSingleObject(t, INFINITE);
    CloseHandle(t);
    return 1;
}
#else
#include <dlfcn.h>
#include <pthread.h>
typedef struct {
    void (*run)(void *);
    void *arg;
} ThreadJob;
static void *thread_start(void *job) {
    ((ThreadJob *)job)->run(((ThreadJob *)job)->arg);
    return NULL;
}
static int on_another_thread(void (*run)(void *), void *arg) {
    ThreadJob job = {run, arg};
    pthread_t t;
    if (pthread_create(&t, NULL, thread_start, &job)) return 0;
    pthread_join(t, NULL);
    return 1;
}
typedef void *Library;
static Library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(Library lib, const char *name) { return dlsym(lib, name); }
static void print_load_error(const char *path) {
    fprintf(stderr, "dlopen %s failed: %s\n", path, dlerror());
}
#endif

/* ---- the FMI 2.0 types this driver uses (fmi2TypesPlatform.h) ---- */
typedef void *fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Boolean;
typedef int fmi2Integer;
typedef int fmi2Status; /* fmi2OK = 0, fmi2Error = 3 */
enum { fmi2OK = 0, fmi2Error = 3, fmi2CoSimulation = 1 };
typedef struct {
    void (*logger)(void *, const char *, fmi2Status, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, fmi2Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

typedef const char *(*GetStringF)(void);
typedef fmi2Component (*InstantiateF)(const char *, int, const char *, const char *,
                                      const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef void (*FreeInstanceF)(fmi2Component);
typedef fmi2Status (*SetupExperimentF)(fmi2Component, fmi2Boolean, double, double, fmi2Boolean,
                                       double);
typedef fmi2Status (*ComponentF)(fmi2Component);
typedef fmi2Status (*SetRealF)(fmi2Component, const fmi2ValueReference *, size_t, const double *);
typedef fmi2Status (*GetRealF)(fmi2Component, const fmi2ValueReference *, size_t, double *);
typedef fmi2Status (*SetIntF)(fmi2Component, const fmi2ValueReference *, size_t, const int *);
typedef fmi2Status (*GetIntF)(fmi2Component, const fmi2ValueReference *, size_t, int *);
typedef fmi2Status (*DoStepF)(fmi2Component, double, double, fmi2Boolean);

static struct {
    GetStringF get_version, get_types_platform;
    InstantiateF instantiate;
    FreeInstanceF free_instance;
    SetupExperimentF setup_experiment;
    ComponentF enter_initialization_mode, exit_initialization_mode, terminate;
    SetRealF set_real;
    GetRealF get_real;
    SetIntF set_integer, set_boolean;
    GetIntF get_integer, get_boolean;
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
static void logger(void *env, const char *instance, fmi2Status status, const char *category,
                   const char *message, ...) {
    char text[4096];
    va_list args;
    (void)env;
    (void)instance;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args); /* the FMU doubles every '%' */
    va_end(args);
    printf("log %d %s %s\n", status, category, text);
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
static char guid[256];
static fmi2ValueReference inputs[MAX_VARS], outputs[MAX_VARS];
static char output_types[MAX_VARS]; /* 'r', 'i', 'b' */
static size_t n_inputs, n_outputs;
static fmi2ValueReference nan_input;
static int has_nan_input;

static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

static fmi2Component instantiate(const char *location, fmi2Boolean logging_on) {
    return fmi.instantiate("driver", fmi2CoSimulation, guid, location, &callbacks, 0, logging_on);
}

/* Wrong calls mid-run: an unknown value reference, NaN for an input (the
 * input keeps its value), a NULL component. */
static void misuse_mid_run(fmi2Component c) {
    const fmi2ValueReference unknown = 0x7fffffffu;
    double x = 1.0;
    check("set_real_unknown_vr", fmi.set_real(c, &unknown, 1, &x), fmi2Error);
    check("get_real_unknown_vr", fmi.get_real(c, &unknown, 1, &x), fmi2Error);
    check("get_real_null_component", fmi.get_real(NULL, &outputs[0], 1, &x), fmi2Error);
    check("do_step_null_component", fmi.do_step(NULL, 0.0, 1e-3, 1), fmi2Error);
    if (has_nan_input) {
        double before, after, nan = NAN;
        check("get_input_before_nan", fmi.get_real(c, &nan_input, 1, &before), fmi2OK);
        check("set_real_nan_input", fmi.set_real(c, &nan_input, 1, &nan), fmi2Error);
        check("get_input_after_nan", fmi.get_real(c, &nan_input, 1, &after), fmi2OK);
        check("nan_left_input_unchanged", bits_of(after) == bits_of(before), 1);
    }
}

/* The calls of `calls_from_another_thread`'s second thread. */
typedef struct {
    fmi2Component c;
    double y;
    int refused;
} Hop;
static void hop_calls(void *arg) {
    Hop *hop = arg;
    for (int k = 0; k < 40; k++) {
        double y = NAN;
        if (fmi.get_real(hop->c, &outputs[0], 1, &y) == fmi2OK)
            hop->y = y;
        else
            hop->refused++;
    }
}

/* The instance used from a second thread, one thread at a time. */
static void calls_from_another_thread(fmi2Component c) {
    Hop hop = {c, NAN, 0};
    double y = NAN;
    check("thread_started", on_another_thread(hop_calls, &hop), 1);
    check("calls_from_another_thread_refused", hop.refused, 0);
    check("get_real_back_on_the_first_thread", fmi.get_real(c, &outputs[0], 1, &y), fmi2OK);
    check("both_threads_read_the_same", bits_of(hop.y) == bits_of(y), 1);
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: %s LIBRARY PLAN RESOURCE_URI [URI...]\n", argv[0]);
        return 2;
    }
    Library lib = open_library(argv[1]);
    if (!lib) {
        print_load_error(argv[1]);
        return 2;
    }
    fmi.get_version = (GetStringF)require(lib, "fmi2GetVersion");
    fmi.get_types_platform = (GetStringF)require(lib, "fmi2GetTypesPlatform");
    fmi.instantiate = (InstantiateF)require(lib, "fmi2Instantiate");
    fmi.free_instance = (FreeInstanceF)require(lib, "fmi2FreeInstance");
    fmi.setup_experiment = (SetupExperimentF)require(lib, "fmi2SetupExperiment");
    fmi.enter_initialization_mode = (ComponentF)require(lib, "fmi2EnterInitializationMode");
    fmi.exit_initialization_mode = (ComponentF)require(lib, "fmi2ExitInitializationMode");
    fmi.terminate = (ComponentF)require(lib, "fmi2Terminate");
    fmi.set_real = (SetRealF)require(lib, "fmi2SetReal");
    fmi.get_real = (GetRealF)require(lib, "fmi2GetReal");
    fmi.set_integer = (SetIntF)require(lib, "fmi2SetInteger");
    fmi.get_integer = (GetIntF)require(lib, "fmi2GetInteger");
    fmi.set_boolean = (SetIntF)require(lib, "fmi2SetBoolean");
    fmi.get_boolean = (GetIntF)require(lib, "fmi2GetBoolean");
    fmi.do_step = (DoStepF)require(lib, "fmi2DoStep");
    printf("version %s\nplatform %s\n", fmi.get_version(), fmi.get_types_platform());

    FILE *plan = fopen(argv[2], "r");
    if (!plan) {
        fprintf(stderr, "cannot open %s\n", argv[2]);
        return 2;
    }
    char line[8192];
    fmi2Component c = NULL;
    double t = 0.0;
    long steps = 0, line_no = 0;
    int initialized = 0, checked_mid_run = 0;
    long mid_run = -1; /* the step before which misuse_mid_run runs */
    while (fgets(line, sizeof line, plan)) {
        char *word = strtok(line, " \t\r\n");
        line_no++;
        if (!word || word[0] == '#') continue;
        if (!strcmp(word, "guid")) {
            snprintf(guid, sizeof guid, "%s", strtok(NULL, " \t\r\n"));
            /* A GUID this library does not hold: refused. */
            fmi2Component wrong = fmi.instantiate("driver", fmi2CoSimulation,
                                                  "{00000000-0000-0000-0000-000000000000}",
                                                  argv[3], &callbacks, 0, 0);
            check("instantiate_wrong_guid_is_null", wrong == NULL, 1);
            /* Every further location: created, logging what it read. */
            for (int i = 4; i < argc; i++) {
                fmi2Component other = instantiate(argv[i], 1);
                printf("uri %s\n", argv[i]);
                check("instantiate_with_uri", other != NULL, 1);
                if (other) fmi.free_instance(other);
            }
            c = instantiate(argv[3], 0);
            check("instantiate", c != NULL, 1);
            if (!c) return 1;
            /* Wrong state: no step and no exit before initialization. */
            check("do_step_before_initialization", fmi.do_step(c, 0.0, 1e-3, 1), fmi2Error);
            check("exit_initialization_before_enter", fmi.exit_initialization_mode(c), fmi2Error);
        } else if (!c) {
            fprintf(stderr, "%s:%ld: the plan must start with its guid\n", argv[2], line_no);
            return 2;
        } else if (!strcmp(word, "real") || !strcmp(word, "integer") || !strcmp(word, "boolean")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
            const char *value = strtok(NULL, " \t\r\n");
            fmi2Status s;
            if (word[0] == 'r') {
                double x = real_of(value);
                s = fmi.set_real(c, &vr, 1, &x);
            } else {
                int n = atoi(value);
                s = word[0] == 'i' ? fmi.set_integer(c, &vr, 1, &n) : fmi.set_boolean(c, &vr, 1, &n);
            }
            check("set_parameter", s, fmi2OK);
        } else if (!strcmp(word, "input")) {
            inputs[n_inputs++] = (fmi2ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
        } else if (!strcmp(word, "output")) {
            const char *type = strtok(NULL, " \t\r\n");
            output_types[n_outputs] = type[0];
            outputs[n_outputs++] = (fmi2ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
        } else if (!strcmp(word, "nan_input")) {
            nan_input = (fmi2ValueReference)strtoul(strtok(NULL, " \t\r\n"), NULL, 10);
            has_nan_input = 1;
        } else if (!strcmp(word, "steps")) {
            mid_run = strtol(strtok(NULL, " \t\r\n"), NULL, 10) / 2;
        } else if (!strcmp(word, "step")) {
            double h = real_of(strtok(NULL, " \t\r\n")), u[MAX_VARS];
            if (!initialized) {
                check("setup_experiment", fmi.setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
                check("enter_initialization_mode", fmi.enter_initialization_mode(c), fmi2OK);
                check("exit_initialization_mode", fmi.exit_initialization_mode(c), fmi2OK);
                initialized = 1;
            }
            for (size_t i = 0; i < n_inputs; i++) u[i] = real_of(strtok(NULL, " \t\r\n"));
            if (n_inputs && fmi.set_real(c, inputs, n_inputs, u) != fmi2OK)
                check("set_inputs", 1, 0);
            if (steps == mid_run) {
                misuse_mid_run(c);
                if (n_outputs && output_types[0] == 'r') calls_from_another_thread(c);
                checked_mid_run = 1;
            }
            if (fmi.do_step(c, t, h, 1) != fmi2OK) {
                printf("do_step at t = %.17g failed\n", t);
                check("do_step", 1, 0);
                break;
            }
            t += h;
            steps++;
            printf("o %016llx", (unsigned long long)bits_of(t));
            for (size_t i = 0; i < n_outputs; i++) {
                double y = NAN;
                int n = 0;
                fmi2Status s = output_types[i] == 'r' ? fmi.get_real(c, &outputs[i], 1, &y)
                               : output_types[i] == 'i' ? fmi.get_integer(c, &outputs[i], 1, &n)
                                                        : fmi.get_boolean(c, &outputs[i], 1, &n);
                if (s != fmi2OK) check("get_output", s, fmi2OK);
                if (output_types[i] == 'r')
                    printf(" %016llx", (unsigned long long)bits_of(y));
                else
                    printf(" %d", n);
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
    check("terminate", fmi.terminate(c), fmi2OK);
    fmi.free_instance(c);
    printf("steps %ld\nfailures %d\n", steps, failures);
    return failures ? 1 : 0;
}
