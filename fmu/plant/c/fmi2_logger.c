/* The FMI 2.0 logger an FMU plant hands to its FMU (fmi2CallbackFunctions.logger). The
 * callback is variadic, which stable Rust cannot define, so this shim formats the message
 * (FMI 2.0 §2.1.5: `message` is a printf format) and hands it to the Rust side,
 * `uio_fmi2_log` (fmu/plant/src/fmi2.rs). Any string argument may be NULL (pythonfmu passes
 * a NULL category): the Rust side reads none that is. */
#include <stdarg.h>
#include <stdio.h>

extern void uio_fmi2_log(const char *instance, int status, const char *category, const char *text);

void uio_fmi2_logger(void *env, const char *instance, int status, const char *category,
                     const char *message, ...) {
    (void)env;
    char text[2048];
    if (!message) {
        text[0] = 0;
    } else {
        va_list ap;
        va_start(ap, message);
        vsnprintf(text, sizeof text, message, ap);
        va_end(ap);
    }
    uio_fmi2_log(instance, status, category, text);
}
