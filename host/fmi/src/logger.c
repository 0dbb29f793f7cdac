/* The FMI 2.0 logger callback (FMI 2.0.4 §2.1.5, fmi2CallbackLogger).
 *
 * It is variadic (`message` is a printf format), which stable Rust cannot
 * define, so it is written here: the message is formatted with vsnprintf
 * into a stack buffer, or into a heap buffer of the exact size when it does
 * not fit, and the finished string goes to the Rust sink
 * `fricsim_log_sink` (logger.rs). */

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

/* Implemented in Rust (src/fmu/logger.rs). */
void fricsim_log_sink(void *env, const char *instance_name, int status, const char *category,
                      const char *message);

void fricsim_fmi2_logger(void *env, const char *instance_name, int status, const char *category,
                         const char *message, ...) {
    char stack[1024];
    va_list args;
    va_list again;
    int needed;

    if (message == NULL) {
        fricsim_log_sink(env, instance_name, status, category, "(null message)");
        return;
    }
    va_start(args, message);
    va_copy(again, args);
    needed = vsnprintf(stack, sizeof stack, message, args);
    va_end(args);

    if (needed < 0) {
        /* Not formattable: pass the format itself on, unformatted. */
        fricsim_log_sink(env, instance_name, status, category, message);
    } else if ((size_t)needed < sizeof stack) {
        fricsim_log_sink(env, instance_name, status, category, stack);
    } else {
        size_t size = (size_t)needed + 1;
        char *heap = malloc(size);
        if (heap != NULL && vsnprintf(heap, size, message, again) >= 0) {
            fricsim_log_sink(env, instance_name, status, category, heap);
        } else {
            /* Out of memory: the truncated text is better than nothing. */
            fricsim_log_sink(env, instance_name, status, category, stack);
        }
        free(heap);
    }
    va_end(again);
}
