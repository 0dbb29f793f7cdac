/* Instantiate / run / free cycles of one FMU binary, for scripts/leak-check.sh
 * (run under valgrind). Each cycle: fmi2Instantiate, fmi2SetupExperiment,
 * fmi2Enter/ExitInitializationMode, a few fmi2SetReal/fmi2DoStep/fmi2GetReal
 * steps, an FMU state taken, serialized, deserialized, restored and freed,
 * a refused call (so that an error message is built and logged),
 * fmi2Terminate and fmi2FreeInstance. The library is loaded once.
 *
 *   leak_cycles <binary.so> <GUID> <cycles> [dlclose]
 *
 * The library stays loaded until exit (as in an importer that loads it
 * once), unless "dlclose" is given: a Rust library's one-time statics (the
 * model registry built on first use) are then unmapped with the pointers
 * to them, and valgrind reports them lost, the same bytes whatever the
 * number of cycles.
 *
 * Exit status 0 when every call returned the expected status. */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void *C;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;

static int messages;
static void logger(void *env, const char *name, int status, const char *category,
                   const char *message, ...) {
    (void)env; (void)name; (void)status; (void)category; (void)message;
    messages++;
}

static void *sym(void *lib, const char *name) {
    void *f = dlsym(lib, name);
    if (!f) { fprintf(stderr, "missing %s\n", name); exit(2); }
    return f;
}

#define CHECK(call, expected) do { int s_ = (call); if (s_ != (expected)) { \
    fprintf(stderr, "cycle %d: %s returned %d\n", cycle, #call, s_); return 1; } } while (0)

int main(int argc, char **argv) {
    if (argc != 4 && argc != 5) {
        fprintf(stderr, "usage: %s lib.so GUID cycles [dlclose]\n", argv[0]);
        return 2;
    }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); return 2; }
    const char *guid = argv[2];
    int cycles = atoi(argv[3]);
    C (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int) =
        sym(lib, "fmi2Instantiate");
    void (*free_instance)(C) = sym(lib, "fmi2FreeInstance");
    int (*setup)(C, int, double, double, int, double) = sym(lib, "fmi2SetupExperiment");
    int (*enter)(C) = sym(lib, "fmi2EnterInitializationMode");
    int (*exit_)(C) = sym(lib, "fmi2ExitInitializationMode");
    int (*terminate)(C) = sym(lib, "fmi2Terminate");
    int (*set_real)(C, const unsigned *, size_t, const double *) = sym(lib, "fmi2SetReal");
    int (*get_real)(C, const unsigned *, size_t, double *) = sym(lib, "fmi2GetReal");
    int (*do_step)(C, double, double, int) = sym(lib, "fmi2DoStep");
    int (*get_state)(C, void **) = sym(lib, "fmi2GetFMUstate");
    int (*set_state)(C, void *) = sym(lib, "fmi2SetFMUstate");
    int (*free_state)(C, void **) = sym(lib, "fmi2FreeFMUstate");
    int (*state_size)(C, void *, size_t *) = sym(lib, "fmi2SerializedFMUstateSize");
    int (*serialize)(C, void *, char *, size_t) = sym(lib, "fmi2SerializeFMUstate");
    int (*deserialize)(C, const char *, size_t, void **) = sym(lib, "fmi2DeSerializeFMUstate");
    Callbacks cb = {logger, NULL, NULL, NULL, NULL};
    const unsigned input = 0, unknown = 99999;
    double checksum = 0;
    for (int cycle = 0; cycle < cycles; cycle++) {
        C c = instantiate("leak", 1, guid, "file:///tmp", &cb, 0, 0);
        if (!c) { fprintf(stderr, "cycle %d: fmi2Instantiate returned NULL\n", cycle); return 1; }
        CHECK(setup(c, 0, 0.0, 0.0, 0, 0.0), 0);
        CHECK(enter(c), 0);
        CHECK(exit_(c), 0);
        double t = 0.0, h = 1e-3, y = 0.0;
        for (int k = 0; k < 5; k++) {
            double u = 1e-6 * sin(10.0 * t);
            CHECK(set_real(c, &input, 1, &u), 0);
            CHECK(do_step(c, t, h, 1), 0);
            t += h;
            CHECK(get_real(c, &input, 1, &y), 0);
            checksum += y;
        }
        void *s = NULL, *s2 = NULL;
        size_t n = 0;
        CHECK(get_state(c, &s), 0);
        CHECK(state_size(c, s, &n), 0);
        char *bytes = malloc(n);
        CHECK(serialize(c, s, bytes, n), 0);
        CHECK(deserialize(c, bytes, n, &s2), 0);
        CHECK(deserialize(c, bytes, n / 2, &s2 == NULL ? NULL : &(void *){NULL}), 3);
        free(bytes);
        CHECK(set_state(c, s2), 0);
        CHECK(free_state(c, &s), 0);
        CHECK(free_state(c, &s2), 0);
        CHECK(get_real(c, &unknown, 1, &y), 3);
        CHECK(do_step(c, t, h, 1), 0);
        CHECK(terminate(c), 0);
        free_instance(c);
    }
    printf("%d cycles, %d messages, checksum %g\n", cycles, messages, checksum);
    if (argc == 5) dlclose(lib);
    return 0;
}
