/*
 * fmu_host: the smallest FMI 2.0 co-simulation host, in C, for checking that
 * a wire_fmu (pythonfmu) FMU runs outside Python.
 *
 *   fmu_host UNZIPPED_FMU_DIR VARIABLE [STEPS [STEP [thread]]]
 *
 * Reads modelIdentifier, guid and VARIABLE's valueReference from
 * UNZIPPED_FMU_DIR/modelDescription.xml (plain text search, enough for the
 * files our builder writes), dlopen()s binaries/linux64/<modelIdentifier>.so,
 * instantiates it, initialises it with its start values, takes STEPS steps
 * of STEP seconds (default 10 x 0.01 s) and prints "t value" after each.
 * With "thread" the steps are taken on a thread of the host's own, as a C++
 * master's worker threads take them, and the host then prints
 * "thread_states N": how many Python thread states the interpreter holds.
 * Exit status 0 on success, 1 on any FMI error.
 *
 * The host leaves with _exit() and never dlclose()s the FMU: a pythonfmu
 * binary finalises its embedded Python (Py_Finalize, from a static
 * destructor on its own thread) when the library is unloaded or the process
 * exits, and with numpy/scipy imported that finalisation can crash in the
 * garbage collector after all FMI work is done.
 *
 * Build (headers from FMPy): gcc -o fmu_host fmu_host.c -I<fmpy>/c-code -ldl -lpthread
 * Run with libpython preloaded, see docs/interop.md.
 */
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list args;
    (void)env;
    fprintf(stderr, "[%s %d %s] ", instance ? instance : "?", (int)status,
            category ? category : "");
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fputc('\n', stderr);
}

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *text;
    long size;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    size = ftell(f);
    fseek(f, 0, SEEK_SET);
    text = calloc((size_t)size + 1, 1);
    if (text && fread(text, 1, (size_t)size, f) != (size_t)size) {
        free(text);
        text = NULL;
    }
    fclose(f);
    return text;
}

/* Copy the value of attribute `name` found at or after `from` into `out`. */
static int attribute(const char *from, const char *name, char *out, size_t size)
{
    char key[128];
    const char *start, *end;
    snprintf(key, sizeof key, " %s=\"", name);
    start = strstr(from, key);
    if (!start) return 0;
    start += strlen(key);
    end = strchr(start, '"');
    if (!end || (size_t)(end - start) >= size) return 0;
    memcpy(out, start, (size_t)(end - start));
    out[end - start] = '\0';
    return 1;
}

static void *symbol(void *lib, const char *name)
{
    void *f = dlsym(lib, name);
    if (!f) fprintf(stderr, "fmu_host: %s not found: %s\n", name, dlerror());
    return f;
}

typedef struct {
    fmi2DoStepTYPE *do_step;
    fmi2GetRealTYPE *get_real;
    fmi2Component c;
    fmi2ValueReference vr;
    int steps;
    double step;
    int failed;
} Steps;

/* Take the steps, printing "t value" after each; failed = 1 on an FMI error. */
static void *take_steps(void *arg)
{
    Steps *s = arg;
    double t = 0.0, value = 0.0;
    int i;
    for (i = 0; i < s->steps; i++) {
        if (s->do_step(s->c, t, s->step, fmi2True) > fmi2Warning
            || s->get_real(s->c, &s->vr, 1, &value) > fmi2Warning) {
            fprintf(stderr, "fmu_host: step %d failed\n", i);
            s->failed = 1;
            return NULL;
        }
        t += s->step;
        printf("%.17g %.17g\n", t, value);
    }
    return NULL;
}

/* Python thread states in the main interpreter (libpython's symbols, preloaded). */
static int thread_states(void)
{
    void *(*main_interpreter)(void) = dlsym(RTLD_DEFAULT, "PyInterpreterState_Main");
    void *(*head)(void *) = dlsym(RTLD_DEFAULT, "PyInterpreterState_ThreadHead");
    void *(*next)(void *) = dlsym(RTLD_DEFAULT, "PyThreadState_Next");
    int n = 0;
    void *state;
    if (!main_interpreter || !head || !next) return -1;
    for (state = head(main_interpreter()); state; state = next(state)) n++;
    return n;
}

int main(int argc, char **argv)
{
    char path[4096], id[256], guid[256], vr_text[32], key[512], uri[4200];
    const char *dir, *variable, *where;
    char *xml;
    int steps = argc > 3 ? atoi(argv[3]) : 10;
    double step = argc > 4 ? atof(argv[4]) : 0.01;
    fmi2ValueReference vr;
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    void *lib;
    fmi2Component c;

    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc < 3) {
        fprintf(stderr, "usage: fmu_host UNZIPPED_FMU_DIR VARIABLE [STEPS [STEP [thread]]]\n");
        return 2;
    }
    dir = argv[1];
    variable = argv[2];
    snprintf(path, sizeof path, "%s/modelDescription.xml", dir);
    xml = read_file(path);
    if (!xml || !attribute(xml, "modelIdentifier", id, sizeof id)
        || !attribute(xml, "guid", guid, sizeof guid)) {
        fprintf(stderr, "fmu_host: cannot read %s\n", path);
        return 1;
    }
    snprintf(key, sizeof key, " name=\"%s\"", variable);
    where = strstr(xml, key);
    if (!where || !attribute(where, "valueReference", vr_text, sizeof vr_text)) {
        fprintf(stderr, "fmu_host: no variable %s in %s\n", variable, path);
        return 1;
    }
    vr = (fmi2ValueReference)strtoul(vr_text, NULL, 10);

    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, id);
    lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "fmu_host: dlopen failed: %s\n", dlerror());
        return 1;
    }
    {
        fmi2InstantiateTYPE *instantiate = symbol(lib, "fmi2Instantiate");
        fmi2SetupExperimentTYPE *setup = symbol(lib, "fmi2SetupExperiment");
        fmi2EnterInitializationModeTYPE *enter = symbol(lib, "fmi2EnterInitializationMode");
        fmi2ExitInitializationModeTYPE *exit_init = symbol(lib, "fmi2ExitInitializationMode");
        fmi2DoStepTYPE *do_step = symbol(lib, "fmi2DoStep");
        fmi2GetRealTYPE *get_real = symbol(lib, "fmi2GetReal");
        fmi2TerminateTYPE *terminate = symbol(lib, "fmi2Terminate");
        fmi2FreeInstanceTYPE *free_instance = symbol(lib, "fmi2FreeInstance");
        if (!instantiate || !setup || !enter || !exit_init || !do_step || !get_real
            || !terminate || !free_instance) return 1;

        snprintf(uri, sizeof uri, "file://%s/resources", dir);
        c = instantiate("host", fmi2CoSimulation, guid, uri, &callbacks, fmi2False, fmi2False);
        if (!c) {
            fprintf(stderr, "fmu_host: fmi2Instantiate failed\n");
            return 1;
        }
        if (setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) > fmi2Warning
            || enter(c) > fmi2Warning || exit_init(c) > fmi2Warning) {
            fprintf(stderr, "fmu_host: initialisation failed\n");
            return 1;
        }
        {
            Steps s = {do_step, get_real, c, vr, steps, step, 0};
            if (argc > 5 && strcmp(argv[5], "thread") == 0) {
                pthread_t worker;
                if (pthread_create(&worker, NULL, take_steps, &s) != 0
                    || pthread_join(worker, NULL) != 0) {
                    fprintf(stderr, "fmu_host: no thread\n");
                    return 1;
                }
                if (!s.failed) printf("thread_states %d\n", thread_states());
            } else {
                take_steps(&s);
            }
            if (s.failed) return 1;
        }
        terminate(c);
        free_instance(c);
    }
    free(xml);
    fflush(stdout);
    _exit(0); /* not exit(): see the note at the top */
}
